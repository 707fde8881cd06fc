#include "stages/calibrate/residuals/lidar_position_sample_cost_function.h"

namespace tiltcal::calibrate {

LidarPositionSampleCostFunction::LidarPositionSampleCostFunction(double u, double inv_dt,
                                                                 const Eigen::Matrix3d& a_from_b,
                                                                 const Eigen::Vector3d& measured,
                                                                 double sigma_m)
    : basis_(spline::UniformCubicBasis(u, inv_dt)),
      a_from_b_(a_from_b),
      measured_(measured),
      inv_sigma_(1.0 / sigma_m) {}

bool LidarPositionSampleCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                               double** jacobians) const {
  Eigen::Vector3d p = a_from_b_ * Eigen::Map<const Eigen::Vector3d>(parameters[4]) - measured_;
  for (int j = 0; j < 4; ++j) p += basis_.value[j] * Eigen::Map<const Eigen::Vector3d>(parameters[j]);
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = inv_sigma_ * p;
  if (jacobians == nullptr) return true;
  for (int j = 0; j < 4; ++j) {
    if (jacobians[j] == nullptr) continue;
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> jac(jacobians[j]);
    jac = (inv_sigma_ * basis_.value[j]) * Eigen::Matrix3d::Identity();
  }
  if (jacobians[4] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> jac(jacobians[4]);
    jac = inv_sigma_ * a_from_b_;
  }
  return true;
}

}  // namespace tiltcal::calibrate
