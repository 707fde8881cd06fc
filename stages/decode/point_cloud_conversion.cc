#include "stages/decode/point_cloud_conversion.h"

#include <cmath>
#include <cstring>
#include <optional>

#include "common/checked_conversion.h"
#include "stages/decode/fast_point_conversion.h"
#include "stages/decode/point_field_layout.h"
#include "stages/decode/point_validity.h"

namespace tiltcal {

namespace {

using decode::CloudLayout;
using decode::FastColumns;
using decode::FastResult;
using decode::PointCheck;
using ros1::PointCloud2View;
using ros1::PointField;

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
        if (!decode::IsValidRelativeSeconds(v)) return false;
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
      const PointCheck check = decode::CheckPoint(x, y, z, min_range2);
      if (check != PointCheck::kValid) {
        ++(check == PointCheck::kInvalid ? result->dropped_invalid : result->dropped_range);
        continue;
      }
      int64_t offset_ns = 0;
      if (!time.OffsetNs(p, &offset_ns)) {
        ++result->dropped_invalid;
        continue;
      }
      if (!decode::FitsInt32(offset_ns)) {
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
  TILTCAL_RETURN_IF_ERROR(decode::FindCloudLayout(cloud, &layout));
  const uint64_t num_points = uint64_t{cloud.width} * cloud.height;
  if (num_points == 0) {
    scan->set_time_source(layout.source);
    return Status::Ok();
  }
  TILTCAL_RETURN_IF_ERROR(decode::CheckCloudDataSize(cloud));

  const bool with_ring = layout.ring.present;
  const FastColumns columns = ReserveColumns(static_cast<int>(num_points), with_ring, scan);
  const double min_range2 = options.min_range_m * options.min_range_m;
  const decode::FastConverter fast =
      options.allow_fast_path ? decode::PickFastConverter(cloud.is_bigendian, layout) : nullptr;
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
