#include "stages/calibrate/residuals/gyro_cost_function.h"

#include "common/imu/triad_errors.h"
#include "common/spline/so3_spline.h"
#include "stages/calibrate/residuals/jacobian_writer.h"

namespace tiltcal::calibrate {

GyroCostFunction::GyroCostFunction(const spline::KnotWindow& window, double inv_dt,
                                   const Eigen::Vector3d& measured_radps, double sigma_radps)
    : u_(window.u), inv_dt_(inv_dt), measured_radps_(measured_radps), inv_sigma_(1.0 / sigma_radps) {}

bool GyroCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                double** jacobians) const {
  const bool knot_jacobians = KnotJacobiansRequested(jacobians);
  spline::So3SplineSample s;
  spline::EvaluateSo3Spline(
      parameters, u_, inv_dt_,
      spline::kSo3AngularVelocity | (knot_jacobians ? spline::kSo3AngularVelocityJacobian : 0), &s);
  const Eigen::Map<const Eigen::Vector3d> bias(parameters[4]);
  Eigen::Map<Eigen::Vector3d> r(residuals);
  const Eigen::Matrix3d sensor =
      Eigen::Matrix3d::Identity() + imu::TriadErrorsMatrix(parameters[5]);  // I + E_g
  r = inv_sigma_ * (sensor * s.angular_velocity + bias - measured_radps_);

  if (jacobians == nullptr) return true;
  const Eigen::Matrix3d sensor_scaled = inv_sigma_ * sensor;
  for (int i = 0; i < 4; ++i) {
    if (jacobians[i] == nullptr) continue;
    const Eigen::Matrix3d jt = sensor_scaled * s.angular_velocity_jacobian[i];
    WriteQuaternionJacobian<3>(jt, parameters[i], jacobians[i]);
  }
  if (jacobians[4] != nullptr) {
    WriteJacobian<3, 3>(inv_sigma_ * Eigen::Matrix3d::Identity(), jacobians[4]);
  }
  if (jacobians[5] != nullptr) {
    WriteJacobian<3, imu::kTriadErrorsSize>(inv_sigma_ * imu::TriadErrorsJacobian(s.angular_velocity),
                                           jacobians[5]);
  }
  return true;
}

}  // namespace tiltcal::calibrate
