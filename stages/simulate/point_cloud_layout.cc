#include "stages/simulate/point_cloud_layout.h"

#include <algorithm>
#include <cstring>
#include <vector>

#include "bag/ros1/message_encoding.h"

namespace tiltcal::simulate {

namespace {

using ros1::kFloat32;
using ros1::kUint16;
using ros1::kUint32;
using ros1::kUint8;

template <typename T>
inline void Put(char* base, uint32_t offset, T value) {
  std::memcpy(base + offset, &value, sizeof(T));
}

}  // namespace

bool SerializeScan(const SimulatedScan& scan, bool ouster, bool append_label, uint32_t seq,
                   int64_t stamp_ns, const std::string& frame_id, std::string* message) {
  std::vector<ros1::PointField> fields;
  uint32_t step = 0;
  if (!ouster) {
    fields = {{"x", 0, kFloat32, 1},        {"y", 4, kFloat32, 1},
              {"z", 8, kFloat32, 1},        {"intensity", 12, kFloat32, 1},
              {"ring", 16, kUint16, 1},     {"time", 18, kFloat32, 1}};
    step = 22;
    if (append_label) {
      fields.push_back({"label", 22, kUint8, 1});
      step = 23;
    }
  } else {
    fields = {{"x", 0, kFloat32, 1},          {"y", 4, kFloat32, 1},
              {"z", 8, kFloat32, 1},          {"intensity", 16, kFloat32, 1},
              {"t", 20, kUint32, 1},          {"reflectivity", 24, kUint16, 1},
              {"ring", 26, kUint16, 1},       {"ambient", 28, kUint16, 1},
              {"range", 32, kUint32, 1}};
    if (append_label) fields.push_back({"label", 30, kUint8, 1});
    step = 48;
  }
  const size_t n = scan.points.size();
  std::string data(n * step, '\0');
  char* base = data.data();
  for (size_t i = 0; i < n; ++i) {
    const ScanPoint& p = scan.points[i];
    char* q = base + i * step;
    Put(q, 0, p.x);
    Put(q, 4, p.y);
    Put(q, 8, p.z);
    if (!ouster) {
      Put(q, 12, p.intensity);
      Put(q, 16, p.ring);
      Put(q, 18, p.time_s);
      if (append_label) Put(q, 22, p.label);
    } else {
      Put(q, 16, p.intensity);
      Put(q, 20, p.time_ns);
      Put(q, 24, p.reflectivity);
      Put(q, 26, p.ring);
      Put(q, 28, static_cast<uint16_t>(0));
      if (append_label) Put(q, 30, p.label);
      Put(q, 32, p.range_mm);
    }
  }
  const uint32_t height = ouster ? static_cast<uint32_t>(scan.rows) : 1u;
  const uint32_t width = ouster ? static_cast<uint32_t>(scan.columns) : static_cast<uint32_t>(n);
  const bool dense = !ouster || scan.num_valid == n;
  return ros1::SerializePointCloud2(seq, stamp_ns, frame_id, height, width, fields, step, data, dense,
                              message);
}

bool SerializeLivoxScan(const SimulatedScan& scan, uint32_t seq, int64_t stamp_ns,
                        const std::string& frame_id, std::string* message) {
  std::vector<ros1::LivoxPoint> points(scan.points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const ScanPoint& p = scan.points[i];
    ros1::LivoxPoint& q = points[i];
    q.offset_time = p.time_ns;
    q.x = p.x;
    q.y = p.y;
    q.z = p.z;
    q.reflectivity = static_cast<uint8_t>(std::min<uint16_t>(p.reflectivity, 255));
    q.tag = p.tag;
    q.line = static_cast<uint8_t>(p.ring);
  }
  return ros1::SerializeLivoxCustomMsg(seq, stamp_ns, frame_id, /*lidar_id=*/1, points, message);
}

}  // namespace tiltcal::simulate
