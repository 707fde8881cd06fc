#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_ACCEL_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_ACCEL_COST_FUNCTION_H_

// Accelerometer residual of one IMU sample at IMU time t (docs/design.md §6):
//   r = ((I + E_a) C_ab(t)^T (r''_a(t) - g_a) + b_a - f_m) / sigma_a   (3, dimensionless)
// C_ab(t): SO(3) spline (IMU b -> world a); r''_a(t): second time derivative
// of the R^3 position spline r_a^{ba}(t), m/s^2; E_a: the accelerometer
// triad's scale and axis errors (common/imu/triad_errors.h), lower
// triangular (its upper entries held at zero by the problem builder's
// manifold): the accelerometer triad defines frame b.
//
// Gravity: g_a = gravity_norm_mps2 * n_g, with the unit direction n_g (world
// frame a, pointing DOWN, i.e. g_a ~ (0, 0, -9.81) when a's z is up) a
// 3-double parameter block on ceres::SphereManifold<3> (2 DoF). The norm is
// fixed (CalibrateParams.gravity_norm_mps2) and passed at construction.
//
// Parameter blocks, in order:
//   0..3  rotation knots s..s+3: unit quaternions, 4 doubles (x, y, z, w),
//         spline::RightQuaternionManifold (right perturbation);
//   4..7  position knots s..s+3: 3 doubles each, m;
//   8     gravity direction n_g: 3 doubles, unit, SphereManifold<3>;
//   9     accelerometer bias b_a: 3 doubles, m/s^2;
//   10    accelerometer errors E_a: 9 doubles row-major (held constant when
//         the IMU intrinsics are not estimated).
// (s, u) fixed at construction (IMU time is not optimised). Analytic
// Jacobians; robust losses are applied by the problem builder.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "common/spline/knot_grid.h"

namespace tiltcal::calibrate {

class AccelCostFunction final : public ceres::SizedCostFunction<3, 4, 4, 4, 4, 3, 3, 3, 3, 3, 3, 9> {
 public:
  AccelCostFunction(const spline::KnotWindow& window, double inv_dt,
                    const Eigen::Vector3d& measured_mps2, double sigma_mps2,
                    double gravity_norm_mps2);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double u_;
  double inv_dt_;
  Eigen::Vector4d position_weights_;  // d^2 b_j / dt^2, 1/s^2
  Eigen::Vector3d measured_mps2_;
  double inv_sigma_;
  double gravity_norm_mps2_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_ACCEL_COST_FUNCTION_H_
