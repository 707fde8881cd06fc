#ifndef TILTCAL_STAGES_DECODE_POINT_FIELD_LAYOUT_H_
#define TILTCAL_STAGES_DECODE_POINT_FIELD_LAYOUT_H_

// The fields of a sensor_msgs/PointCloud2 that the conversion to a Scan reads
// (point_cloud_conversion.h lists the names and types), found in its
// PointField list, and the checks of its size fields against its data.

#include <cstdint>
#include <cstring>

#include "bag/ros1/messages.h"
#include "common/status.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::decode {

// Reads one value of `type` at `p` (unaligned), byte-swapped when `swap`.
template <typename T>
inline T LoadValue(const uint8_t* p, bool swap) {
  if (!swap) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    return value;
  }
  uint8_t bytes[sizeof(T)];
  for (size_t i = 0; i < sizeof(T); ++i) bytes[i] = p[sizeof(T) - 1 - i];
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

// One field to read as a number.
struct PointFieldAccessor {
  bool present = false;
  uint32_t offset = 0;
  uint8_t type = 0;
  const char* name = "";

  double Get(const uint8_t* point, bool swap) const {
    const uint8_t* p = point + offset;
    switch (type) {
      case ros1::kInt8: return static_cast<int8_t>(*p);
      case ros1::kUint8: return *p;
      case ros1::kInt16: return LoadValue<int16_t>(p, swap);
      case ros1::kUint16: return LoadValue<uint16_t>(p, swap);
      case ros1::kInt32: return LoadValue<int32_t>(p, swap);
      case ros1::kUint32: return LoadValue<uint32_t>(p, swap);
      case ros1::kFloat32: return LoadValue<float>(p, swap);
      case ros1::kFloat64: return LoadValue<double>(p, swap);
      default: return 0.0;
    }
  }
};

// The fields of a cloud that the conversion reads, and its time convention.
struct CloudLayout {
  PointFieldAccessor x, y, z, intensity, ring;
  PointFieldAccessor time;                 // the one time field, except for SEC_NSEC
  PointFieldAccessor time_sec, time_nsec;  // POINT_TIME_SEC_NSEC
  proto::PointTimeSource source = proto::POINT_TIME_NONE;
};

// Finds the fields of `cloud`: x, y, z (required), intensity, ring and the
// per-point time, each with its datatype checked.
Status FindCloudLayout(const ros1::PointCloud2View& cloud, CloudLayout* layout);

// Checks that the data block holds height rows of width points (rows
// row_step apart, points point_step apart), for a cloud with points.
Status CheckCloudDataSize(const ros1::PointCloud2View& cloud);

}  // namespace tiltcal::decode

#endif  // TILTCAL_STAGES_DECODE_POINT_FIELD_LAYOUT_H_
