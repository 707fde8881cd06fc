#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_LIDAR_POSITION_SAMPLE_COST_FUNCTION_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_LIDAR_POSITION_SAMPLE_COST_FUNCTION_H_

// A measured position of the LiDAR origin in the world a at IMU time t
// (initialisation's position fit: the LiDAR odometry's positions), with the
// IMU orientation C_ab(t) held at the rotation spline's value (the rotation
// knots are constant in that fit):
//   r = (p_ab(t) + C_ab(t) r_b^{lb} - p_l,measured) / sigma    (3, dimensionless)
//   p_ab(t) = sum_j b_j(u) p_{s+j},  j = 0..3
// p_ab(t): the position spline (cubic B-spline basis b_j at the knot
// window's u, spline::UniformCubicBasis); r_b^{lb}: the lever arm, frame b,
// m; sigma in m per axis.
//
// Parameter blocks: position knots s..s+3 (3 each, m, frame a), then
// r_b^{lb} (3, m). Analytic Jacobians:
//   dr/dp_{s+j} = b_j(u) / sigma I,   dr/dr_b^{lb} = C_ab(t) / sigma.

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "common/spline/cubic_basis.h"

namespace tiltcal::calibrate {

class LidarPositionSampleCostFunction final
    : public ceres::SizedCostFunction<3, 3, 3, 3, 3, 3> {
 public:
  // u in [0, 1) within the knot window, inv_dt = 1 / knot spacing (1/s),
  // a_from_b = C_ab(t), measured = p_l,measured (m, frame a).
  LidarPositionSampleCostFunction(double u, double inv_dt, const Eigen::Matrix3d& a_from_b,
                                  const Eigen::Vector3d& measured, double sigma_m);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  spline::CubicBasis basis_;
  Eigen::Matrix3d a_from_b_;
  Eigen::Vector3d measured_;
  double inv_sigma_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_LIDAR_POSITION_SAMPLE_COST_FUNCTION_H_
