#include "stages/decode/point_cloud_conversion.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <type_traits>

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

// ---------------------------------------------------------------- fast path --
// One loop per common layout, types fixed at compile time: no per-point type
// switch and no libm call. Every value is computed exactly as in the generic
// loop of ConvertPointCloud2ToScan (same double intermediates, same checks in
// the same order), so both give the same bytes.

struct NoField {};

template <typename T>
inline T Load(const uint8_t* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}

// std::llround(v) for |v| < 2^52 (half away from zero): v - trunc(v) is exact.
inline int64_t RoundHalfAwayFromZero(double v) {
  const int64_t i = static_cast<int64_t>(v);
  const double fraction = v - static_cast<double>(i);
  return i + static_cast<int64_t>(fraction >= 0.5) - static_cast<int64_t>(fraction <= -0.5);
}

enum class FastTime { kNone, kVelodyneFloat32, kOusterUint32 };

struct FastColumns {
  float* x;
  float* y;
  float* z;
  float* intensity;
  uint32_t* ring;  // null when the cloud has no ring field
  int32_t* time_offset_ns;
};

struct FastResult {
  int count = 0;
  uint32_t dropped_invalid = 0;
  uint32_t dropped_range = 0;
};

// Converts all points; false when a time offset leaves int32 (the generic
// loop then reruns the cloud and reports the error).
template <typename IntensityT, typename RingT, FastTime kTime>
bool ConvertFast(const PointCloud2View& cloud, const uint32_t offsets[6], double min_range2,
                 const FastColumns& out, FastResult* result) {
  const uint32_t ox = offsets[0], oy = offsets[1], oz = offsets[2];
  const uint32_t oi = offsets[3], orng = offsets[4], ot = offsets[5];
  const uint64_t width = cloud.width;
  const uint32_t step = cloud.point_step;
  // Local copies: the column stores could otherwise alias `out` and `cloud`
  // and force reloads of the pointers on every point.
  float* const xs = out.x;
  float* const ys = out.y;
  float* const zs = out.z;
  float* const is = out.intensity;
  uint32_t* const rs = out.ring;
  int32_t* const ts = out.time_offset_ns;
  const uint8_t* const data = cloud.data;
  const uint64_t height = cloud.height;
  const uint64_t row_step = cloud.row_step;
  uint32_t dropped_invalid = 0;
  uint32_t dropped_range = 0;
  int k = 0;
  for (uint64_t r = 0; r < height; ++r) {
    const uint8_t* p = data + r * row_step;
    for (uint64_t c = 0; c < width; ++c, p += step) {
      const float x = Load<float>(p + ox);
      const float y = Load<float>(p + oy);
      const float z = Load<float>(p + oz);
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
      int64_t offset_ns = 0;
      if constexpr (kTime == FastTime::kVelodyneFloat32) {
        const double v = Load<float>(p + ot);  // s relative to the stamp
        if (!(std::isfinite(v) && std::fabs(v) < 1e3)) {
          ++dropped_invalid;
          continue;
        }
        offset_ns = RoundHalfAwayFromZero(v * 1e9);
      } else if constexpr (kTime == FastTime::kOusterUint32) {
        offset_ns = Load<uint32_t>(p + ot);  // ns relative to the stamp, exact
      }
      if (offset_ns < std::numeric_limits<int32_t>::min() ||
          offset_ns > std::numeric_limits<int32_t>::max()) {
        return false;
      }
      xs[k] = x;
      ys[k] = y;
      zs[k] = z;
      if constexpr (std::is_same_v<IntensityT, NoField>) {
        is[k] = 0.0f;
      } else {
        is[k] = static_cast<float>(static_cast<double>(Load<IntensityT>(p + oi)));
      }
      if constexpr (!std::is_same_v<RingT, NoField>) {
        rs[k] = static_cast<uint32_t>(Load<RingT>(p + orng));
      }
      ts[k] = static_cast<int32_t>(offset_ns);
      ++k;
    }
  }
  result->count = k;
  result->dropped_invalid = dropped_invalid;
  result->dropped_range = dropped_range;
  return true;
}

using FastConverter = bool (*)(const PointCloud2View&, const uint32_t[6], double,
                               const FastColumns&, FastResult*);

template <typename IntensityT, typename RingT>
FastConverter PickTime(FastTime time) {
  switch (time) {
    case FastTime::kNone: return &ConvertFast<IntensityT, RingT, FastTime::kNone>;
    case FastTime::kVelodyneFloat32:
      return &ConvertFast<IntensityT, RingT, FastTime::kVelodyneFloat32>;
    case FastTime::kOusterUint32: return &ConvertFast<IntensityT, RingT, FastTime::kOusterUint32>;
  }
  return nullptr;
}

template <typename IntensityT>
FastConverter PickRing(const Accessor& ring, FastTime time) {
  if (!ring.present) return PickTime<IntensityT, NoField>(time);
  switch (ring.type) {
    case ros1::kUint8: return PickTime<IntensityT, uint8_t>(time);
    case ros1::kUint16: return PickTime<IntensityT, uint16_t>(time);
    default: return nullptr;
  }
}

// The specialised loop for this layout, or null when the generic loop must run.
FastConverter PickFastConverter(bool swap, const Accessor& ax, const Accessor& ay,
                                const Accessor& az, const Accessor& intensity,
                                const Accessor& ring, proto::PointTimeSource source,
                                const Accessor& time) {
  if (swap || ax.type != ros1::kFloat32 || ay.type != ros1::kFloat32 ||
      az.type != ros1::kFloat32) {
    return nullptr;
  }
  FastTime fast_time;
  if (source == proto::POINT_TIME_NONE) {
    fast_time = FastTime::kNone;
  } else if (source == proto::POINT_TIME_VELODYNE_TIME && time.type == ros1::kFloat32) {
    fast_time = FastTime::kVelodyneFloat32;
  } else if (source == proto::POINT_TIME_OUSTER_T && time.type == ros1::kUint32) {
    fast_time = FastTime::kOusterUint32;
  } else {
    return nullptr;
  }
  if (!intensity.present) return PickRing<NoField>(ring, fast_time);
  switch (intensity.type) {
    case ros1::kFloat32: return PickRing<float>(ring, fast_time);
    case ros1::kUint8: return PickRing<uint8_t>(ring, fast_time);
    case ros1::kUint16: return PickRing<uint16_t>(ring, fast_time);
    default: return nullptr;
  }
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
  const FastConverter fast =
      options.allow_fast_path
          ? PickFastConverter(swap, ax, ay, az, intensity, ring, source, time)
          : nullptr;
  FastResult fast_result;
  const uint32_t offsets[6] = {ax.offset,   ay.offset,   az.offset,
                               intensity.offset, ring.offset, time.offset};
  const bool fast_done =
      fast != nullptr && fast(cloud, offsets, min_range2, FastColumns{xs, ys, zs, is, rs, ts},
                              &fast_result);
  if (fast_done) {
    k = fast_result.count;
    dropped_invalid = fast_result.dropped_invalid;
    dropped_range = fast_result.dropped_range;
  }
  for (uint64_t r = 0; r < (fast_done ? 0 : height); ++r) {
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
