#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_DENSE_SAMPLE_WEIGHT_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_DENSE_SAMPLE_WEIGHT_H_

// The LiDAR residuals' weight in the calibration's final, denser round
// (OuterLoopParams.final_association; docs/design.md §7). The points of a
// denser sample are correlated (neighbours on one surfel in one scan share
// the plane's error), so a sample of n residuals that stands for one of
// n_reference is given (n / n_reference)^e times the reference sample's
// information, e = information_exponent in [0, 1]:
//   sigma_m'      = sigma_m * (n / n_reference)^((1 - e) / 2)
//   cauchy_scale' = cauchy_scale / (n / n_reference)^((1 - e) / 2)
// (the Cauchy scale is in units of sigma: the loss bends at the same
// distance in metres). n_reference = 0 or n <= n_reference: unchanged.

#include <cmath>
#include <cstddef>

#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

inline proto::LidarResidualParams DenseSampleLidarParams(const proto::LidarResidualParams& lidar,
                                                         size_t n, size_t n_reference,
                                                         double information_exponent) {
  proto::LidarResidualParams out = lidar;
  if (n_reference == 0 || n <= n_reference) return out;
  const double scale = std::pow(static_cast<double>(n) / static_cast<double>(n_reference),
                                0.5 * (1.0 - information_exponent));
  out.set_sigma_m(lidar.sigma_m() * scale);
  out.set_cauchy_scale(lidar.cauchy_scale() / scale);
  return out;
}

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_DENSE_SAMPLE_WEIGHT_H_
