#include "stages/decode/point_cloud_conversion.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>

#include "common/checked_conversion.h"

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

// Outcome of the validity rule for one point.
enum class PointCheck { kValid, kInvalid, kTooClose };

// The validity rule of every point, shared by the fast and the generic loop:
// a NaN or Inf coordinate is invalid; a point at zero range, or with
// x² + y² + z² (in double) below min_range_m², is too close.
inline PointCheck CheckPoint(float x, float y, float z, double min_range2) {
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) return PointCheck::kInvalid;
  const double range2 =
      static_cast<double>(x) * x + static_cast<double>(y) * y + static_cast<double>(z) * z;
  if (range2 == 0.0 || range2 < min_range2) return PointCheck::kTooClose;
  return PointCheck::kValid;
}

// A per-point time in seconds relative to the stamp (Velodyne `time`) is
// valid when finite and within 1000 s of the stamp.
inline bool IsValidRelativeSeconds(double v) { return std::isfinite(v) && std::fabs(v) < 1e3; }

// A per-point time offset must fit the int32 ns column (+-2.147 s).
inline bool FitsInt32(int64_t offset_ns) {
  return offset_ns >= std::numeric_limits<int32_t>::min() &&
         offset_ns <= std::numeric_limits<int32_t>::max();
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
      const PointCheck check = CheckPoint(x, y, z, min_range2);
      if (check != PointCheck::kValid) {
        ++(check == PointCheck::kInvalid ? dropped_invalid : dropped_range);
        continue;
      }
      int64_t offset_ns = 0;
      if constexpr (kTime == FastTime::kVelodyneFloat32) {
        const double v = Load<float>(p + ot);  // s relative to the stamp
        if (!IsValidRelativeSeconds(v)) {
          ++dropped_invalid;
          continue;
        }
        offset_ns = RoundHalfAwayFromZero(v * 1e9);
      } else if constexpr (kTime == FastTime::kOusterUint32) {
        offset_ns = Load<uint32_t>(p + ot);  // ns relative to the stamp, exact
      }
      if (!FitsInt32(offset_ns)) return false;
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

// The fields of a cloud that the conversion reads, and its time convention.
struct CloudLayout {
  Accessor x, y, z, intensity, ring;
  Accessor time;                 // the one time field, except for SEC_NSEC
  Accessor time_sec, time_nsec;  // POINT_TIME_SEC_NSEC
  proto::PointTimeSource source = proto::POINT_TIME_NONE;
};

// The specialised loop for this layout, or null when the generic loop must run.
FastConverter PickFastConverter(bool swap, const CloudLayout& layout) {
  if (swap || layout.x.type != ros1::kFloat32 || layout.y.type != ros1::kFloat32 ||
      layout.z.type != ros1::kFloat32) {
    return nullptr;
  }
  FastTime fast_time;
  if (layout.source == proto::POINT_TIME_NONE) {
    fast_time = FastTime::kNone;
  } else if (layout.source == proto::POINT_TIME_VELODYNE_TIME &&
             layout.time.type == ros1::kFloat32) {
    fast_time = FastTime::kVelodyneFloat32;
  } else if (layout.source == proto::POINT_TIME_OUSTER_T && layout.time.type == ros1::kUint32) {
    fast_time = FastTime::kOusterUint32;
  } else {
    return nullptr;
  }
  if (!layout.intensity.present) return PickRing<NoField>(layout.ring, fast_time);
  switch (layout.intensity.type) {
    case ros1::kFloat32: return PickRing<float>(layout.ring, fast_time);
    case ros1::kUint8: return PickRing<uint8_t>(layout.ring, fast_time);
    case ros1::kUint16: return PickRing<uint16_t>(layout.ring, fast_time);
    default: return nullptr;
  }
}

// The per-point time: `time_sec` + `time_nsec`, else the first present of
// `timestamp`, `t`, `time`, `offset_time`, each with its datatype checked.
Status FindTimeFields(const PointCloud2View& cloud, CloudLayout* layout) {
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"time_sec"}, &layout->time_sec));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"time_nsec"}, &layout->time_nsec));
  const Accessor& sec = layout->time_sec;
  const Accessor& nsec = layout->time_nsec;
  if (sec.present && nsec.present) {
    TILTCAL_RETURN_IF_ERROR(RequireType(sec, IsInteger(sec.type), "an integer type"));
    TILTCAL_RETURN_IF_ERROR(RequireType(nsec, IsInteger(nsec.type), "an integer type"));
    layout->source = proto::POINT_TIME_SEC_NSEC;
    return Status::Ok();
  }
  // The first of these names present decides the convention.
  Accessor& time = layout->time;
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"timestamp", "t", "time", "offset_time"}, &time));
  if (!time.present) return Status::Ok();
  const std::string name = time.name;
  if (name == "timestamp") {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, time.type == ros1::kFloat64, "FLOAT64"));
    layout->source = proto::POINT_TIME_ABSOLUTE_SECONDS;  // or ns, decided on the values
  } else if (name == "t") {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, IsInteger(time.type), "an integer type (ns)"));
    layout->source = proto::POINT_TIME_OUSTER_T;
  } else if (name == "time") {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, IsFloat(time.type), "FLOAT32 or FLOAT64 (s)"));
    layout->source = proto::POINT_TIME_VELODYNE_TIME;
  } else {
    TILTCAL_RETURN_IF_ERROR(RequireType(time, IsInteger(time.type), "an integer type (ns)"));
    layout->source = proto::POINT_TIME_OFFSET_TIME_NS;
  }
  return Status::Ok();
}

Status FindLayout(const PointCloud2View& cloud, CloudLayout* layout) {
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"x"}, &layout->x));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"y"}, &layout->y));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"z"}, &layout->z));
  if (!layout->x.present || !layout->y.present || !layout->z.present) {
    return Status::Error("PointCloud2 lacks an x, y or z field (fields: " +
                         DescribeFields(cloud) + ")");
  }
  for (const Accessor* a : {&layout->x, &layout->y, &layout->z}) {
    TILTCAL_RETURN_IF_ERROR(RequireType(*a, IsFloat(a->type), "FLOAT32 or FLOAT64"));
  }
  TILTCAL_RETURN_IF_ERROR(
      FindField(cloud, {"intensity", "i", "reflectivity"}, &layout->intensity));
  TILTCAL_RETURN_IF_ERROR(FindField(cloud, {"ring", "line", "laser_id"}, &layout->ring));
  return FindTimeFields(cloud, layout);
}

// Checks that the data block holds height rows of width points (rows
// row_step apart, points point_step apart), for a cloud with points.
Status CheckDataSize(const PointCloud2View& cloud) {
  const uint64_t width = cloud.width;
  const uint64_t height = cloud.height;
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
  if (width * height > static_cast<uint64_t>(std::numeric_limits<int>::max())) {
    return Status::Error("PointCloud2 has too many points: " + std::to_string(width * height));
  }
  return Status::Ok();
}

// Reads the per-point time offset from the stamp, ns, of each point. For
// `timestamp` fields the first valid value decides between absolute seconds
// and absolute ns as a double (values above 1e12: seconds since 1970 stay
// below that until the year 33658), which updates source().
class PointTimeReader {
 public:
  PointTimeReader(const CloudLayout& layout, ros1::RosTime stamp, bool swap)
      : layout_(layout),
        source_(layout.source),
        swap_(swap),
        stamp_ns_(ros1::RosTimeToNs(stamp)),
        stamp_sec_(static_cast<double>(stamp.sec)),
        stamp_nsec_(static_cast<double>(stamp.nsec)) {}

  // False when the point's time is not a valid value (the point is invalid).
  bool OffsetNs(const uint8_t* p, int64_t* offset_ns) {
    *offset_ns = 0;
    switch (source_) {
      case proto::POINT_TIME_VELODYNE_TIME: {
        const double v = layout_.time.Get(p, swap_);  // s relative to the stamp
        if (!IsValidRelativeSeconds(v)) return false;
        *offset_ns = std::llround(v * 1e9);
        return true;
      }
      case proto::POINT_TIME_OUSTER_T:
      case proto::POINT_TIME_OFFSET_TIME_NS:
        *offset_ns = static_cast<int64_t>(layout_.time.Get(p, swap_));  // ns relative, exact
        return true;
      case proto::POINT_TIME_ABSOLUTE_SECONDS:
      case proto::POINT_TIME_ABSOLUTE_NS_DOUBLE:
        return AbsoluteOffsetNs(layout_.time.Get(p, swap_), offset_ns);
      case proto::POINT_TIME_SEC_NSEC: {
        const int64_t sec = static_cast<int64_t>(layout_.time_sec.Get(p, swap_));
        const int64_t nsec = static_cast<int64_t>(layout_.time_nsec.Get(p, swap_));
        *offset_ns = sec * 1000000000 + nsec - stamp_ns_;
        return true;
      }
      default:  // POINT_TIME_NONE, POINT_TIME_SIMULATED: all offsets 0
        return true;
    }
  }

  proto::PointTimeSource source() const { return source_; }
  // The field named in errors about the time.
  std::string field_name() const {
    return source_ == proto::POINT_TIME_SEC_NSEC ? "time_sec" : layout_.time.name;
  }

 private:
  bool AbsoluteOffsetNs(double v, int64_t* offset_ns) {
    if (!(std::isfinite(v) && v >= 0.0 && v < 9e18)) return false;
    if (!decided_ns_double_) {
      if (v > 1e12) source_ = proto::POINT_TIME_ABSOLUTE_NS_DOUBLE;
      decided_ns_double_ = true;
    }
    if (source_ == proto::POINT_TIME_ABSOLUTE_NS_DOUBLE) {
      *offset_ns = std::llround(v) - stamp_ns_;
      return true;
    }
    // v - sec is exact (both within a factor of 2 for times near the stamp),
    // so only the final scaling rounds.
    const double rel = (v - stamp_sec_) * 1e9 - stamp_nsec_;
    if (!(std::fabs(rel) < 9e18)) return false;
    *offset_ns = std::llround(rel);
    return true;
  }

  const CloudLayout& layout_;
  proto::PointTimeSource source_;
  const bool swap_;
  const int64_t stamp_ns_;
  const double stamp_sec_;
  const double stamp_nsec_;
  bool decided_ns_double_ = false;
};

// The loop for any layout: every value through its type's accessor. Fills
// the columns with the valid points; *source is the time convention found.
Status ConvertGeneric(const PointCloud2View& cloud, const CloudLayout& layout,
                      double min_range2, const FastColumns& out, FastResult* result,
                      proto::PointTimeSource* source) {
  const bool swap = cloud.is_bigendian;
  const bool fast_xyz = !swap && layout.x.type == ros1::kFloat32 &&
                        layout.y.type == ros1::kFloat32 && layout.z.type == ros1::kFloat32;
  PointTimeReader time(layout, cloud.header.stamp, swap);
  const uint64_t width = cloud.width;
  int k = 0;
  for (uint64_t r = 0; r < cloud.height; ++r) {
    const uint8_t* row = cloud.data + r * cloud.row_step;
    for (uint64_t c = 0; c < width; ++c) {
      const uint8_t* p = row + c * cloud.point_step;
      float x, y, z;
      if (fast_xyz) {
        std::memcpy(&x, p + layout.x.offset, 4);
        std::memcpy(&y, p + layout.y.offset, 4);
        std::memcpy(&z, p + layout.z.offset, 4);
      } else {
        x = static_cast<float>(layout.x.Get(p, swap));
        y = static_cast<float>(layout.y.Get(p, swap));
        z = static_cast<float>(layout.z.Get(p, swap));
      }
      const PointCheck check = CheckPoint(x, y, z, min_range2);
      if (check != PointCheck::kValid) {
        ++(check == PointCheck::kInvalid ? result->dropped_invalid : result->dropped_range);
        continue;
      }
      int64_t offset_ns = 0;
      if (!time.OffsetNs(p, &offset_ns)) {
        ++result->dropped_invalid;
        continue;
      }
      if (!FitsInt32(offset_ns)) {
        return Status::Error("point " + std::to_string(r * width + c) + ": its time (field '" +
                             time.field_name() + "') is " +
                             std::to_string(static_cast<double>(offset_ns) * 1e-9) +
                             " s from header.stamp; offsets must stay within +-2.147 s "
                             "(point times in another clock than the stamp?)");
      }
      if (out.ring != nullptr) {
        // A float or signed ring field may hold what no ring number is.
        const double ring = layout.ring.Get(p, swap);
        const std::optional<uint32_t> checked = CheckedTruncate<uint32_t>(ring);
        if (!checked) {
          return Status::Error("point " + std::to_string(r * width + c) + ": its ring (field '" +
                               layout.ring.name + "') is " + std::to_string(ring) +
                               ", not a ring number");
        }
        out.ring[k] = *checked;
      }
      out.x[k] = x;
      out.y[k] = y;
      out.z[k] = z;
      out.intensity[k] =
          layout.intensity.present ? static_cast<float>(layout.intensity.Get(p, swap)) : 0.0f;
      out.time_offset_ns[k] = static_cast<int32_t>(offset_ns);
      ++k;
    }
  }
  result->count = k;
  *source = time.source();
  return Status::Ok();
}

// Clears `scan` and sets the fields known before the points are read.
void ResetScan(const PointCloud2View& cloud, proto::Scan* scan) {
  scan->clear_x();
  scan->clear_y();
  scan->clear_z();
  scan->clear_intensity();
  scan->clear_ring();
  scan->clear_time_offset_ns();
  scan->set_stamp_ns(ros1::RosTimeToNs(cloud.header.stamp));
  scan->set_frame_id(cloud.header.frame_id);
  scan->set_num_dropped_invalid(0);
  scan->set_num_dropped_zero_range(0);
  scan->set_num_dropped_noise_tag(0);
  scan->set_time_source(proto::POINT_TIME_NONE);
}

// Columns of n values written in place (no per-point allocation), truncated
// to the points kept by FinishColumns.
FastColumns ReserveColumns(int n, bool with_ring, proto::Scan* scan) {
  auto reserve = [n](auto* column) {
    column->Reserve(n);
    return column->AddNAlreadyReserved(n);
  };
  FastColumns columns;
  columns.x = reserve(scan->mutable_x());
  columns.y = reserve(scan->mutable_y());
  columns.z = reserve(scan->mutable_z());
  columns.intensity = reserve(scan->mutable_intensity());
  columns.ring = with_ring ? reserve(scan->mutable_ring()) : nullptr;
  columns.time_offset_ns = reserve(scan->mutable_time_offset_ns());
  return columns;
}

void FinishColumns(const FastResult& result, bool with_ring, proto::Scan* scan) {
  const int k = result.count;
  scan->mutable_x()->Truncate(k);
  scan->mutable_y()->Truncate(k);
  scan->mutable_z()->Truncate(k);
  scan->mutable_intensity()->Truncate(k);
  if (with_ring) scan->mutable_ring()->Truncate(k);
  scan->mutable_time_offset_ns()->Truncate(k);
  scan->set_num_dropped_invalid(result.dropped_invalid);
  scan->set_num_dropped_zero_range(result.dropped_range);
}

}  // namespace

// True when `text` is well-formed UTF-8 (no overlong forms, surrogates or
// code points above U+10FFFF), as a protobuf string field must be: a
// Scan with another frame_id would be written but could not be read back.
bool IsValidUtf8(const std::string& text) {
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const size_t n = text.size();
  for (size_t i = 0; i < n;) {
    const unsigned char c = s[i];
    size_t length = 0;
    uint32_t code = 0;
    if (c < 0x80) {
      ++i;
      continue;
    } else if ((c & 0xE0) == 0xC0) {
      length = 2;
      code = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      length = 3;
      code = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      length = 4;
      code = c & 0x07;
    } else {
      return false;
    }
    if (i + length > n) return false;
    for (size_t k = 1; k < length; ++k) {
      if ((s[i + k] & 0xC0) != 0x80) return false;
      code = (code << 6) | (s[i + k] & 0x3F);
    }
    const uint32_t smallest[5] = {0, 0, 0x80, 0x800, 0x10000};
    if (code < smallest[length] || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) {
      return false;
    }
    i += length;
  }
  return true;
}

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
  if (!IsValidUtf8(cloud.header.frame_id)) {
    return Status::Error("header.frame_id is not valid UTF-8");
  }
  ResetScan(cloud, scan);
  CloudLayout layout;
  TILTCAL_RETURN_IF_ERROR(FindLayout(cloud, &layout));
  const uint64_t num_points = uint64_t{cloud.width} * cloud.height;
  if (num_points == 0) {
    scan->set_time_source(layout.source);
    return Status::Ok();
  }
  TILTCAL_RETURN_IF_ERROR(CheckDataSize(cloud));

  const bool with_ring = layout.ring.present;
  const FastColumns columns = ReserveColumns(static_cast<int>(num_points), with_ring, scan);
  const double min_range2 = options.min_range_m * options.min_range_m;
  const FastConverter fast =
      options.allow_fast_path ? PickFastConverter(cloud.is_bigendian, layout) : nullptr;
  const uint32_t offsets[6] = {layout.x.offset,         layout.y.offset,    layout.z.offset,
                               layout.intensity.offset, layout.ring.offset, layout.time.offset};
  FastResult result;
  proto::PointTimeSource source = layout.source;
  if (fast == nullptr || !fast(cloud, offsets, min_range2, columns, &result)) {
    result = FastResult();
    TILTCAL_RETURN_IF_ERROR(
        ConvertGeneric(cloud, layout, min_range2, columns, &result, &source));
  }
  FinishColumns(result, with_ring, scan);
  scan->set_time_source(source);
  return Status::Ok();
}

}  // namespace tiltcal
