#ifndef TILTCAL_STAGES_DECODE_POINT_VALIDITY_H_
#define TILTCAL_STAGES_DECODE_POINT_VALIDITY_H_

// The rules that decide whether a point of a PointCloud2 is kept, shared by
// the loop of any layout (point_cloud_conversion.cc) and the loops compiled
// for common layouts (fast_point_conversion.h).

#include <cmath>
#include <cstdint>
#include <limits>

namespace tiltcal::decode {

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

}  // namespace tiltcal::decode

#endif  // TILTCAL_STAGES_DECODE_POINT_VALIDITY_H_
