#include "stages/inspect/point_cloud_sample.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "common/status.h"

namespace tiltcal::inspect {
namespace {

using ros1::PointCloud2View;
using ros1::PointField;

const PointField* FindField(const PointCloud2View& cloud, const char* name) {
  for (const PointField& f : cloud.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

template <typename T>
double As(const uint8_t* bytes) {
  T v;
  std::memcpy(&v, bytes, sizeof(T));
  return static_cast<double>(v);
}

// One value of `datatype` at `p` as a double (byte-swapped for big-endian);
// NaN for an unknown datatype.
double ReadValue(const uint8_t* p, uint8_t datatype, bool big_endian) {
  uint8_t bytes[8];
  const size_t size = ros1::PointFieldTypeSize(datatype);
  std::memcpy(bytes, p, size);
  if (big_endian) std::reverse(bytes, bytes + size);
  switch (datatype) {
    case ros1::kInt8: return As<int8_t>(bytes);
    case ros1::kUint8: return As<uint8_t>(bytes);
    case ros1::kInt16: return As<int16_t>(bytes);
    case ros1::kUint16: return As<uint16_t>(bytes);
    case ros1::kInt32: return As<int32_t>(bytes);
    case ros1::kUint32: return As<uint32_t>(bytes);
    case ros1::kFloat32: return As<float>(bytes);
    case ros1::kFloat64: return As<double>(bytes);
    default: return std::numeric_limits<double>::quiet_NaN();
  }
}

// How a point's time field becomes an offset from the header stamp, s.
enum class TimeKind { kNone, kSecNsec, kAbsoluteSeconds, kRelativeNs, kRelativeSeconds };

struct TimeFields {
  TimeKind kind = TimeKind::kNone;
  const PointField* field = nullptr;
  const PointField* nsec = nullptr;  // kSecNsec only
};

TimeFields FindTimeFields(const PointCloud2View& cloud) {
  TimeFields t;
  if ((t.field = FindField(cloud, "time_sec")) && (t.nsec = FindField(cloud, "time_nsec"))) {
    t.kind = TimeKind::kSecNsec;
  } else if ((t.field = FindField(cloud, "timestamp"))) {
    t.kind = TimeKind::kAbsoluteSeconds;
  } else if ((t.field = FindField(cloud, "t")) || (t.field = FindField(cloud, "offset_time"))) {
    t.kind = TimeKind::kRelativeNs;
  } else if ((t.field = FindField(cloud, "time"))) {
    t.kind = TimeKind::kRelativeSeconds;
  } else {
    t.field = nullptr;
  }
  return t;
}

const PointField* FindRingField(const PointCloud2View& cloud) {
  for (const char* name : {"ring", "line", "laser_id"}) {
    if (const PointField* f = FindField(cloud, name)) return f;
  }
  return nullptr;
}

Status CheckFieldInsidePoint(const PointCloud2View& cloud, const PointField& f) {
  const size_t size = ros1::PointFieldTypeSize(f.datatype);
  if (size == 0) {
    return Status::Error("field '" + f.name + "' has an unknown datatype " +
                         std::to_string(f.datatype));
  }
  if (f.offset + size > cloud.point_step) {
    return Status::Error("field '" + f.name + "' lies outside the point (offset " +
                         std::to_string(f.offset) + ", point_step " +
                         std::to_string(cloud.point_step) + ")");
  }
  return Status::Ok();
}

double TimeOffsetS(const uint8_t* point, const TimeFields& t, bool big_endian, int64_t stamp_ns) {
  const double v = ReadValue(point + t.field->offset, t.field->datatype, big_endian);
  switch (t.kind) {
    case TimeKind::kSecNsec: {
      const double nsec = ReadValue(point + t.nsec->offset, t.nsec->datatype, big_endian);
      // Whole seconds and nanoseconds apart (a double of the ns stamp would
      // lose the nanoseconds).
      return (v - static_cast<double>(stamp_ns / 1000000000)) +
             1e-9 * (nsec - static_cast<double>(stamp_ns % 1000000000));
    }
    case TimeKind::kAbsoluteSeconds:
      // Values beyond 1e12 are absolute ns (Livox driver 2).
      return v > 1e12 ? 1e-9 * (v - static_cast<double>(stamp_ns))
                      : v - 1e-9 * static_cast<double>(stamp_ns);
    case TimeKind::kRelativeNs:
      return 1e-9 * v;
    case TimeKind::kRelativeSeconds:
      return v;
    case TimeKind::kNone:
      break;
  }
  return 0.0;
}

}  // namespace

CloudLayout DescribeCloudLayout(const PointCloud2View& cloud) {
  CloudLayout layout;
  layout.has_xyz = FindField(cloud, "x") && FindField(cloud, "y") && FindField(cloud, "z");
  const TimeFields t = FindTimeFields(cloud);
  if (t.field) {
    layout.time_field = t.kind == TimeKind::kSecNsec ? "time_sec+time_nsec" : t.field->name;
    layout.time_type = ros1::PointFieldTypeName(t.field->datatype);
    switch (t.kind) {
      case TimeKind::kSecNsec:
        layout.time_meaning = "absolute s + ns";
        break;
      case TimeKind::kAbsoluteSeconds:
        layout.time_meaning = "absolute";
        break;
      case TimeKind::kRelativeNs:
        layout.time_meaning = "ns after the stamp";
        break;
      case TimeKind::kRelativeSeconds:
        layout.time_meaning = "s after the stamp";
        break;
      case TimeKind::kNone:
        break;
    }
  }
  if (const PointField* ring = FindRingField(cloud)) {
    layout.ring_field = ring->name;
    layout.ring_type = ros1::PointFieldTypeName(ring->datatype);
  }
  return layout;
}

Status SampleCloud(const PointCloud2View& cloud, uint32_t stride, CloudSample* sample) {
  sample->x.clear();
  sample->y.clear();
  sample->z.clear();
  sample->has_time = false;
  const PointField* fx = FindField(cloud, "x");
  const PointField* fy = FindField(cloud, "y");
  const PointField* fz = FindField(cloud, "z");
  if (!fx || !fy || !fz) return Status::Error("no x, y, z fields");
  const TimeFields t = FindTimeFields(cloud);
  for (const PointField* f : {fx, fy, fz, t.field, t.nsec}) {
    if (f) TILTCAL_RETURN_IF_ERROR(CheckFieldInsidePoint(cloud, *f));
  }
  const uint64_t row_bytes = static_cast<uint64_t>(cloud.width) * cloud.point_step;
  if (cloud.height > 0 &&
      (cloud.row_step < row_bytes ||
       static_cast<uint64_t>(cloud.row_step) * (cloud.height - 1) + row_bytes > cloud.data_size)) {
    return Status::Error("point data shorter than its " + std::to_string(cloud.height) +
                         " rows of " + std::to_string(cloud.width) + " points");
  }
  const int64_t stamp_ns = ros1::RosTimeToNs(cloud.header.stamp);
  const bool be = cloud.is_bigendian;
  double min_t = std::numeric_limits<double>::infinity(), max_t = -min_t;
  const uint64_t n = static_cast<uint64_t>(cloud.width) * cloud.height;
  for (uint64_t i = 0; i < n; i += stride) {
    const uint8_t* p =
        cloud.data + (i / cloud.width) * cloud.row_step + (i % cloud.width) * cloud.point_step;
    const double x = ReadValue(p + fx->offset, fx->datatype, be);
    const double y = ReadValue(p + fy->offset, fy->datatype, be);
    const double z = ReadValue(p + fz->offset, fz->datatype, be);
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
    if (x == 0.0 && y == 0.0 && z == 0.0) continue;  // no return
    sample->x.push_back(static_cast<float>(x));
    sample->y.push_back(static_cast<float>(y));
    sample->z.push_back(static_cast<float>(z));
    if (!t.field) continue;
    const double offset_s = TimeOffsetS(p, t, be, stamp_ns);
    if (!std::isfinite(offset_s)) continue;
    min_t = std::min(min_t, offset_s);
    max_t = std::max(max_t, offset_s);
  }
  if (min_t <= max_t) {
    sample->has_time = true;
    sample->min_time_offset_s = min_t;
    sample->max_time_offset_s = max_t;
  }
  return Status::Ok();
}

CloudLayout DescribeLivoxLayout() {
  CloudLayout layout;
  layout.has_xyz = true;
  layout.time_field = "offset_time";
  layout.time_type = "UINT32";
  layout.time_meaning = "ns after timebase (Livox CustomMsg)";
  layout.ring_field = "line";
  layout.ring_type = "UINT8";
  return layout;
}

void SampleLivox(const bag::LivoxCustomMessage& msg, uint32_t stride, CloudSample* sample) {
  *sample = CloudSample();
  const int64_t stamp_ns = bag::RosTimeToNs(msg.header.stamp);
  const size_t step = std::max<uint32_t>(stride, 1);
  for (size_t i = 0; i < msg.points.size(); i += step) {
    const bag::LivoxPoint& p = msg.points[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
    sample->x.push_back(p.x);
    sample->y.push_back(p.y);
    sample->z.push_back(p.z);
    // timebase + offset_time − stamp in doubles (no integer overflow for any
    // timebase; ~0.3 µs resolution at today's stamps, enough for a check).
    const double offset_s = (static_cast<double>(msg.timebase) - static_cast<double>(stamp_ns) +
                             static_cast<double>(p.offset_time)) *
                            1e-9;
    if (!sample->has_time) {
      sample->has_time = true;
      sample->min_time_offset_s = sample->max_time_offset_s = offset_s;
    }
    sample->min_time_offset_s = std::min(sample->min_time_offset_s, offset_s);
    sample->max_time_offset_s = std::max(sample->max_time_offset_s, offset_s);
  }
}

}  // namespace tiltcal::inspect
