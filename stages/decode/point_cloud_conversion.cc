#include "stages/decode/point_cloud_conversion.h"

#include <cmath>
#include <cstring>
#include <limits>

namespace tiltcal {

namespace {

using ros1::PointCloud2View;
using ros1::PointField;

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
struct Accessor {
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

bool IsInteger(uint8_t type) { return type >= ros1::kInt8 && type <= ros1::kUint32; }
bool IsFloat(uint8_t type) { return type == ros1::kFloat32 || type == ros1::kFloat64; }

// Finds the first field named one of `names`; checks it fits in a point.
Status FindField(const PointCloud2View& cloud, std::initializer_list<const char*> names,
                 Accessor* accessor) {
  for (const char* name : names) {
    for (const PointField& field : cloud.fields) {
      if (field.name != name) continue;
      const size_t size = ros1::PointFieldTypeSize(field.datatype);
      if (size == 0) {
        return Status::Error("point field '" + field.name + "' has unknown datatype " +
                             std::to_string(field.datatype));
      }
      if (field.count == 0) {
        return Status::Error("point field '" + field.name + "' has count 0");
      }
      if (uint64_t{field.offset} + size > cloud.point_step) {
        return Status::Error("point field '" + field.name + "' (" +
                             ros1::PointFieldTypeName(field.datatype) + " at offset " +
                             std::to_string(field.offset) + ") lies outside the point_step " +
                             std::to_string(cloud.point_step));
      }
      accessor->present = true;
      accessor->offset = field.offset;
      accessor->type = field.datatype;
      accessor->name = name;
      return Status::Ok();
    }
  }
  return Status::Ok();
}

Status RequireType(const Accessor& a, bool ok, const char* expected) {
  if (!a.present || ok) return Status::Ok();
  return Status::Error(std::string("point field '") + a.name + "' has datatype " +
                       ros1::PointFieldTypeName(a.type) + ", expected " + expected);
}

}  // namespace

std::string DescribeFields(const PointCloud2View& cloud) {
  std::string out;
  for (const PointField& f : cloud.fields) {
    if (!out.empty()) out += ' ';
    out += f.name + ":" + ros1::PointFieldTypeName(f.datatype) + "@" + std::to_string(f.offset);
  }
  return out.empty() ? "(none)" : out;
}

Status ConvertPointCloud2ToScan(const PointCloud2View& cloud,
                                const PointConversionOptions& options, proto::Scan* scan) {
  scan->clear_x();
  scan->clear_y();
  scan->clear_z();
  scan->clear_intensity();
  scan->clear_ring();
  scan->clear_time_offset_ns();
  const int64_t stamp_ns = ros1::RosTimeToNs(cloud.header.stamp);
  scan->set_stamp_ns(stamp_ns);
  scan->set_frame_id(cloud.header.frame_id);
  scan->set_num_dropped_invalid(0);
  scan->set_num_dropped_zero_range(0);
  scan->set_time_source(proto::POINT_TIME_NONE);

  // Layout.
  Accessor ax, ay, az, intensity, ring, time, time_sec, time_nsec;
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"x"}, &ax));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"y"}, &ay));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"z"}, &az));
  if (!ax.present || !ay.present || !az.present) {
    return Status::Error("PointCloud2 lacks an x, y or z field (fields: " +
                         DescribeFields(cloud) + ")");
  }
  for (const Accessor* a : {&ax, &ay, &az}) {
    TILTCAL_RETURN_IF_ERROR(RequireType(*a, IsFloat(a->type), "FLOAT32 or FLOAT64"));
  }
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"intensity", "i", "reflectivity"}, &intensity));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"ring", "line", "laser_id"}, &ring));

  proto::PointTimeSource source = proto::POINT_TIME_NONE;
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"time_sec"}, &time_sec));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"time_nsec"}, &time_nsec));
  if (time_sec.present && time_nsec.present) {
    TILTCAL_RETURN_IF_ERROR(RequireType(time_sec, IsInteger(time_sec.type), "an integer type"));
    TILTCAL_RETURN_IF_ERROR(RequireType(time_nsec, IsInteger(time_nsec.type), "an integer type"));
    source = proto::POINT_TIME_SEC_NSEC;
  } else {
    // The first of these names present decides the convention.
    TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"timestamp", "t", "time", "offset_time"}, &time));
    if (time.present) {
      const std::string name = time.name;
      if (name == "timestamp") {
        TILTCAL_RETURN_IF_ERROR(RequireType(time, time.type == ros1::kFloat64, "FLOAT64"));
        source = proto::POINT_TIME_ABSOLUTE_SECONDS;  // or ns, decided on the values below
      } else if (name == "t") {
        TILTCAL_RETURN_IF_ERROR(RequireType(time, IsInteger(time.type), "an integer type (ns)"));
        source = proto::POINT_TIME_OUSTER_T;
      } else if (name == "time") {
        TILTCAL_RETURN_IF_ERROR(RequireType(time, IsFloat(time.type), "FLOAT32 or FLOAT64 (s)"));
        source = proto::POINT_TIME_VELODYNE_TIME;
      } else {
        TILTCAL_RETURN_IF_ERROR(RequireType(time, IsInteger(time.type), "an integer type (ns)"));
        source = proto::POINT_TIME_OFFSET_TIME_NS;
      }
    }
  }

  // Geometry of the data block.
  const uint64_t width = cloud.width;
  const uint64_t height = cloud.height;
  const uint64_t num_points = width * height;
  if (num_points == 0) {
    scan->set_time_source(source);
    return Status::Ok();
  }
  if (cloud.point_step == 0) return Status::Error("PointCloud2 has point_step 0");
  if (uint64_t{cloud.row_step} < width * cloud.point_step && height > 1) {
    return Status::Error("PointCloud2 row_step " + std::to_string(cloud.row_step) +
                         " is smaller than width * point_step = " +
                         std::to_string(width * cloud.point_step));
  }
  // 128 bits: (2^32 - 1)^2 twice does not fit in 64.
  const unsigned __int128 needed =
      static_cast<unsigned __int128>(height - 1) * cloud.row_step +
      static_cast<unsigned __int128>(width) * cloud.point_step;
  if (needed > cloud.data_size) {
    return Status::Error("PointCloud2 data has " + std::to_string(cloud.data_size) +
                         " bytes, " + std::to_string(height) + " rows of " +
                         std::to_string(width) + " points (point_step " +
                         std::to_string(cloud.point_step) + ", row_step " +
                         std::to_string(cloud.row_step) + ") need " +
                         (needed > UINT64_MAX ? std::string("more than 2^64")
                                              : std::to_string(static_cast<uint64_t>(needed))));
  }
  if (num_points > static_cast<uint64_t>(std::numeric_limits<int>::max())) {
    return Status::Error("PointCloud2 has too many points: " + std::to_string(num_points));
  }

  // Columns, written in place (no per-point allocation), truncated at the end.
  const int n = static_cast<int>(num_points);
  auto reserve = [n](auto* column) {
    column->Reserve(n);
    return column->AddNAlreadyReserved(n);
  };
  float* xs = reserve(scan->mutable_x());
  float* ys = reserve(scan->mutable_y());
  float* zs = reserve(scan->mutable_z());
  float* is = reserve(scan->mutable_intensity());
  uint32_t* rs = ring.present ? reserve(scan->mutable_ring()) : nullptr;
  int32_t* ts = reserve(scan->mutable_time_offset_ns());

  const bool swap = cloud.is_bigendian;
  const bool fast_xyz = !swap && ax.type == ros1::kFloat32 && ay.type == ros1::kFloat32 &&
                        az.type == ros1::kFloat32;
  const double min_range2 = options.min_range_m * options.min_range_m;
  const double stamp_sec = static_cast<double>(cloud.header.stamp.sec);
  const double stamp_nsec = static_cast<double>(cloud.header.stamp.nsec);
  bool decided_ns_double = false;
  uint32_t dropped_invalid = 0;
  uint32_t dropped_range = 0;
  int k = 0;
  for (uint64_t r = 0; r < height; ++r) {
    const uint8_t* row = cloud.data + r * cloud.row_step;
    for (uint64_t c = 0; c < width; ++c) {
      const uint8_t* p = row + c * cloud.point_step;
      float x, y, z;
      if (fast_xyz) {
        std::memcpy(&x, p + ax.offset, 4);
        std::memcpy(&y, p + ay.offset, 4);
        std::memcpy(&z, p + az.offset, 4);
      } else {
        x = static_cast<float>(ax.Get(p, swap));
        y = static_cast<float>(ay.Get(p, swap));
        z = static_cast<float>(az.Get(p, swap));
      }
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        ++dropped_invalid;
        continue;
      }
      const double range2 = static_cast<double>(x) * x + static_cast<double>(y) * y +
                            static_cast<double>(z) * z;
      if (range2 == 0.0 || range2 < min_range2) {
        ++dropped_range;
        continue;
      }
      // Per-point time offset from the stamp, ns.
      int64_t offset_ns = 0;
      bool time_ok = true;
      switch (source) {
        case proto::POINT_TIME_NONE:
        case proto::POINT_TIME_SIMULATED:
          break;
        case proto::POINT_TIME_VELODYNE_TIME: {
          const double v = time.Get(p, swap);  // s relative to the stamp
          time_ok = std::isfinite(v) && std::fabs(v) < 1e3;
          if (time_ok) offset_ns = std::llround(v * 1e9);
          break;
        }
        case proto::POINT_TIME_OUSTER_T:
        case proto::POINT_TIME_OFFSET_TIME_NS:
          offset_ns = static_cast<int64_t>(time.Get(p, swap));  // ns relative, exact
          break;
        case proto::POINT_TIME_ABSOLUTE_SECONDS:
        case proto::POINT_TIME_ABSOLUTE_NS_DOUBLE: {
          const double v = time.Get(p, swap);
          time_ok = std::isfinite(v) && v >= 0.0 && v < 9e18;
          if (!time_ok) break;
          if (!decided_ns_double) {
            // Absolute seconds since 1970 stay below 1e12 until year 33658.
            if (v > 1e12) source = proto::POINT_TIME_ABSOLUTE_NS_DOUBLE;
            decided_ns_double = true;
          }
          if (source == proto::POINT_TIME_ABSOLUTE_NS_DOUBLE) {
            offset_ns = std::llround(v) - stamp_ns;
          } else {
            // v - sec is exact (both within a factor of 2 for times near the
            // stamp), so only the final scaling rounds.
            const double rel = (v - stamp_sec) * 1e9 - stamp_nsec;
            time_ok = std::fabs(rel) < 9e18;
            if (time_ok) offset_ns = std::llround(rel);
          }
          break;
        }
        case proto::POINT_TIME_SEC_NSEC: {
          const int64_t sec = static_cast<int64_t>(time_sec.Get(p, swap));
          const int64_t nsec = static_cast<int64_t>(time_nsec.Get(p, swap));
          offset_ns = sec * 1000000000 + nsec - stamp_ns;
          break;
        }
        default:
          break;
      }
      if (!time_ok) {
        ++dropped_invalid;
        continue;
      }
      if (offset_ns < std::numeric_limits<int32_t>::min() ||
          offset_ns > std::numeric_limits<int32_t>::max()) {
        return Status::Error("point " + std::to_string(r * width + c) + ": its time (field '" +
                             (source == proto::POINT_TIME_SEC_NSEC ? std::string("time_sec") :
                                                                     std::string(time.name)) +
                             "') is " + std::to_string(static_cast<double>(offset_ns) * 1e-9) +
                             " s from header.stamp; offsets must stay within +-2.147 s "
                             "(point times in another clock than the stamp?)");
      }
      xs[k] = x;
      ys[k] = y;
      zs[k] = z;
      is[k] = intensity.present ? static_cast<float>(intensity.Get(p, swap)) : 0.0f;
      if (rs != nullptr) rs[k] = static_cast<uint32_t>(ring.Get(p, swap));
      ts[k] = static_cast<int32_t>(offset_ns);
      ++k;
    }
  }
  scan->mutable_x()->Truncate(k);
  scan->mutable_y()->Truncate(k);
  scan->mutable_z()->Truncate(k);
  scan->mutable_intensity()->Truncate(k);
  if (rs != nullptr) scan->mutable_ring()->Truncate(k);
  scan->mutable_time_offset_ns()->Truncate(k);
  scan->set_time_source(source);
  scan->set_num_dropped_invalid(dropped_invalid);
  scan->set_num_dropped_zero_range(dropped_range);
  return Status::Ok();
}

}  // namespace tiltcal
