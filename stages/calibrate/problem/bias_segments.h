#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_BIAS_SEGMENTS_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_BIAS_SEGMENTS_H_

// A slowly wandering IMU bias b(t) (3, the sensor's unit: rad/s for the gyro,
// m/s^2 for the accelerometer) modelled as piecewise constant:
//   b(t) = values[i] for t in [t0 + i S, t0 + (i + 1) S),
// S = segment_s, t0 = the spline start (IMU clock, s). Times before t0 use the
// first segment and times after the last segment use the last one. With
// S = 0 there is one value for the whole sequence. Each values[i] is one
// Ceres parameter block (3 doubles), so the vector must not be resized while
// a ceres::Problem refers to it.

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <fmt/format.h>

#include "common/checked_conversion.h"
#include "common/status.h"

namespace tiltcal::calibrate {

// Shortest bias segment (besides 0 = one segment), s, and the most segments
// one bias may have.
inline constexpr double kMinBiasSegmentS = 1.0;
inline constexpr int kMaxBiasSegments = 100000;

struct BiasSegments {
  double t0_s = 0.0;
  double segment_s = 0.0;  // S; 0 = one segment
  std::vector<std::array<double, 3>> values = {{0.0, 0.0, 0.0}};

  // ceil(duration_s / segment_s) segments from t0_s (one when segment_s <= 0
  // or the duration is shorter), each set to the current mean. More than
  // kMaxBiasSegments (or a count that is not a finite int) is an error naming
  // `field`, the params field of the segment length.
  Status Split(double start_s, double duration_s, double segment_length_s,
               const std::string& field) {
    const Eigen::Vector3d mean = Mean();
    int count = 1;
    if (segment_length_s > 0.0 && duration_s > segment_length_s) {
      const std::optional<int> checked = CheckedCeil<int>(duration_s / segment_length_s);
      if (!checked || *checked > kMaxBiasSegments) {
        return Status::Error(fmt::format(
            "params: {} = {} s cuts the {} s sequence into more than {} bias segments", field,
            segment_length_s, duration_s, kMaxBiasSegments));
      }
      count = *checked;
    }
    t0_s = start_s;
    segment_s = count > 1 ? segment_length_s : 0.0;
    values.assign(count, {mean.x(), mean.y(), mean.z()});
    return Status::Ok();
  }
  int size() const { return static_cast<int>(values.size()); }
  // Index of the segment at time t_s (clamped to the segments).
  int Index(double t_s) const {
    if (segment_s <= 0.0) return 0;
    const double i = std::floor((t_s - t0_s) / segment_s);
    if (std::isnan(i)) return 0;
    return static_cast<int>(std::clamp(i, 0.0, static_cast<double>(size() - 1)));
  }
  double* Block(double t_s) { return values[Index(t_s)].data(); }
  Eigen::Vector3d At(double t_s) const { return Value(Index(t_s)); }
  Eigen::Vector3d Value(int i) const {
    return Eigen::Vector3d(values[i][0], values[i][1], values[i][2]);
  }
  // Mean over the segments.
  Eigen::Vector3d Mean() const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int i = 0; i < size(); ++i) sum += Value(i);
    return sum / static_cast<double>(size());
  }
  // Sets every segment to b.
  void SetAll(const Eigen::Vector3d& b) {
    for (std::array<double, 3>& v : values) v = {b.x(), b.y(), b.z()};
  }
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_BIAS_SEGMENTS_H_
