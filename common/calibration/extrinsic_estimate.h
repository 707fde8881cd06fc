#ifndef TILTCAL_COMMON_CALIBRATION_EXTRINSIC_ESTIMATE_H_
#define TILTCAL_COMMON_CALIBRATION_EXTRINSIC_ESTIMATE_H_

// A calibration's extrinsic, tau and covariance as the estimate that
// common/geometry/extrinsic_fusion.h fuses and compares (docs/design.md §11):
// tangent space (delta C [rad, frame l], r_b^{lb} [m][, tau [s]]).

#include <string>

#include <Eigen/Core>

#include "common/geometry/extrinsic_fusion.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibration {

// Information of the solve's translation prior, n x n (n = 6 or 7; zero:
// none): the solve's covariance holds it unscaled.
Eigen::MatrixXd PriorInformation(const proto::CalibrationResult& result, int n);

// imu_from_lidar, r[, tau], the top-left n x n block of the covariance and
// the prior's information. The result must pass ReasonRefused with n
// (calibration_checks.h).
geometry::ExtrinsicEstimate ToEstimate(const proto::CalibrationResult& result, int n);

// One component of the tangent space (0-2 rotation about l-x, l-y, l-z,
// 3-5 translation along b-x, b-y, b-z, 6 time offset) with a z-score, e.g.
// "rotation about l-y: +98.2 sigma".
std::string DescribeComponent(int component, double z);

}  // namespace tiltcal::calibration

#endif  // TILTCAL_COMMON_CALIBRATION_EXTRINSIC_ESTIMATE_H_
