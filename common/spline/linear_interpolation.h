#ifndef TILTCAL_COMMON_SPLINE_LINEAR_INTERPOLATION_H_
#define TILTCAL_COMMON_SPLINE_LINEAR_INTERPOLATION_H_

#include <algorithm>
#include <cstddef>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::spline {

// Piecewise-linear interpolation of the samples (times[i], values[i]) at t:
// (1 − f) v_{i−1} + f v_i with f = (t − t_{i−1}) / (t_i − t_{i−1}), the first
// or last value outside [times.front(), times.back()]. times ascending and
// the same length as values, at least one sample.
inline Eigen::Vector3d InterpolateLinearly(const std::vector<double>& times,
                                           const std::vector<Eigen::Vector3d>& values,
                                           double t) {
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const size_t i = std::upper_bound(times.begin(), times.end(), t) - times.begin();
  const double f = (t - times[i - 1]) / (times[i] - times[i - 1]);
  return (1.0 - f) * values[i - 1] + f * values[i];
}

}  // namespace tiltcal::spline

#endif  // TILTCAL_COMMON_SPLINE_LINEAR_INTERPOLATION_H_
