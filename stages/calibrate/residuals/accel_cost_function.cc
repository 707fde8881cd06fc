#include "stages/calibrate/residuals/accel_cost_function.h"

#include "common/geometry/so3.h"
#include "common/imu/triad_errors.h"
#include "common/spline/cubic_basis.h"
#include "common/spline/so3_spline.h"
#include "stages/calibrate/residuals/jacobian_writer.h"

namespace tiltcal::calibrate {

AccelCostFunction::AccelCostFunction(const spline::KnotWindow& window, double inv_dt,
                                     const Eigen::Vector3d& measured_mps2, double sigma_mps2,
                                     double gravity_norm_mps2)
    : u_(window.u),
      inv_dt_(inv_dt),
      position_weights_(spline::UniformCubicBasis(window.u, inv_dt).d2),
      measured_mps2_(measured_mps2),
      inv_sigma_(1.0 / sigma_mps2),
      gravity_norm_mps2_(gravity_norm_mps2) {}

bool AccelCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                 double** jacobians) const {
  const bool rotation_jacobians = KnotJacobiansRequested(jacobians);
  spline::So3SplineSample s;
  spline::EvaluateSo3Spline(
      parameters, u_, inv_dt_,
      spline::kSo3Rotation | (rotation_jacobians ? spline::kSo3RotationJacobian : 0), &s);

  Eigen::Vector3d accel = Eigen::Vector3d::Zero();  // r''_a(t)
  for (int j = 0; j < 4; ++j) {
    accel += position_weights_[j] * Eigen::Map<const Eigen::Vector3d>(parameters[4 + j]);
  }
  const Eigen::Map<const Eigen::Vector3d> gravity_dir(parameters[8]);
  const Eigen::Map<const Eigen::Vector3d> bias(parameters[9]);
  const Eigen::Vector3d specific_force_a = accel - gravity_norm_mps2_ * gravity_dir;
  const Eigen::Matrix3d ct = s.rotation.transpose();
  const Eigen::Vector3d specific_force_b = ct * specific_force_a;

  Eigen::Map<Eigen::Vector3d> r(residuals);
  const Eigen::Matrix3d sensor =
      Eigen::Matrix3d::Identity() + imu::TriadErrorsMatrix(parameters[10]);  // I + E_a
  r = inv_sigma_ * (sensor * specific_force_b + bias - measured_mps2_);

  if (jacobians == nullptr) return true;
  const Eigen::Matrix3d sensor_scaled = inv_sigma_ * sensor;
  if (rotation_jacobians) {
    // (C Exp(eps))^T f = C^T f + [C^T f]_x eps.
    const Eigen::Matrix3d d_r_d_eps = sensor_scaled * geometry::Hat(specific_force_b);
    for (int i = 0; i < 4; ++i) {
      if (jacobians[i] == nullptr) continue;
      const Eigen::Matrix3d jt = d_r_d_eps * s.rotation_jacobian[i];
      WriteQuaternionJacobian<3>(jt, parameters[i], jacobians[i]);
    }
  }
  const Eigen::Matrix3d ct_scaled = sensor_scaled * ct;
  for (int j = 0; j < 4; ++j) {
    if (jacobians[4 + j] != nullptr) {
      WriteJacobian<3, 3>(position_weights_[j] * ct_scaled, jacobians[4 + j]);
    }
  }
  if (jacobians[8] != nullptr) {
    WriteJacobian<3, 3>(-gravity_norm_mps2_ * ct_scaled, jacobians[8]);
  }
  if (jacobians[9] != nullptr) {
    WriteJacobian<3, 3>(inv_sigma_ * Eigen::Matrix3d::Identity(), jacobians[9]);
  }
  if (jacobians[10] != nullptr) {
    WriteJacobian<3, imu::kTriadErrorsSize>(inv_sigma_ * imu::TriadErrorsJacobian(specific_force_b),
                                           jacobians[10]);
  }
  return true;
}

}  // namespace tiltcal::calibrate
