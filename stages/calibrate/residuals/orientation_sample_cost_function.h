#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_ORIENTATION_SAMPLE_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_ORIENTATION_SAMPLE_COST_FUNCTION_H_

// A measured orientation of the IMU body at IMU time t (initialisation: the
// LiDAR odometry's orientation carried to b through C_bl):
//   r = Log(C_measured^T C_ab(t)) / sigma              (3, dimensionless)
// C_ab(t): the SO(3) spline (body b to world a); sigma in rad per axis.
// It keeps the heading of a gyro-only rotation spline from drifting away
// from what the LiDAR sees (the gyro bias left after a static start
// integrates to a few tenths of a degree per minute).
//
// Parameter blocks: rotation knots s..s+3, unit quaternions (x, y, z, w),
// spline::RightQuaternionManifold (right perturbation). With
// C_ab(t) <- C_ab(t) Exp(eps):  dr/d eps = J_r^{-1}(r sigma) / sigma.
// Analytic Jacobians.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/spline/knot_grid.h"

namespace tiltcal::calibrate {

class OrientationSampleCostFunction final : public ceres::SizedCostFunction<3, 4, 4, 4, 4> {
 public:
  OrientationSampleCostFunction(const spline::KnotWindow& window, double inv_dt,
                                const Eigen::Quaterniond& measured_a_from_b, double sigma_rad);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double u_;
  double inv_dt_;
  Eigen::Matrix3d measured_transposed_;  // C_measured^T
  double inv_sigma_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_ORIENTATION_SAMPLE_COST_FUNCTION_H_
