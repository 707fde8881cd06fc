#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_GYRO_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_GYRO_COST_FUNCTION_H_

// Gyroscope residual of one IMU sample at IMU time t (docs/design.md §6):
//   r = ((I + E_g) omega_b(t) + b_g - omega_m) / sigma_g     (3, dimensionless)
// omega_b(t): body angular velocity of the SO(3) spline C_ab (Sommer recursion);
// E_g: the gyroscope triad's scale and axis errors (common/imu/triad_errors.h;
// the problem holds its upper triangle at zero, docs/design.md §6).
//
// Parameter blocks, in order:
//   0..3  rotation knots s..s+3: unit quaternions, 4 doubles (x, y, z, w),
//         spline::RightQuaternionManifold (right perturbation);
//   4     gyro bias b_g, 3 doubles, rad/s;
//   5     gyro errors E_g, 9 doubles row-major (held constant when the IMU
//         intrinsics are not estimated).
// The IMU time is not optimised, so (s, u) are fixed at construction.
// Analytic Jacobians; robust losses are the problem builder's business.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "common/spline/knot_grid.h"

namespace tiltcal::calibrate {

class GyroCostFunction final : public ceres::SizedCostFunction<3, 4, 4, 4, 4, 3, 9> {
 public:
  // window: knots and u of the IMU time on the grid (UniformKnotGrid::Locate).
  GyroCostFunction(const spline::KnotWindow& window, double inv_dt,
                   const Eigen::Vector3d& measured_radps, double sigma_radps);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double u_;
  double inv_dt_;
  Eigen::Vector3d measured_radps_;
  double inv_sigma_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_GYRO_COST_FUNCTION_H_
