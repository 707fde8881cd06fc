#include "stages/calibrate/residuals/ground_cost_functions.h"

#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "common/spline/so3_spline.h"
#include "stages/calibrate/residuals/jacobian_writer.h"

namespace tiltcal::calibrate {
namespace {

// Which spline outputs a residual needs, given the requested Jacobians
// (blocks 0..3 are the rotation knots, block 6 is tau).
int SplineOutputs(double** jacobians, bool* knot_jacobians, bool* tau_jacobian) {
  *knot_jacobians = KnotJacobiansRequested(jacobians);
  *tau_jacobian = jacobians != nullptr && jacobians[6] != nullptr;
  return spline::kSo3Rotation | (*knot_jacobians ? spline::kSo3RotationJacobian : 0) |
         (*tau_jacobian ? spline::kSo3AngularVelocity : 0);
}

Eigen::Vector3d UpFromGravity(const Eigen::Vector3d& gravity) { return -gravity.normalized(); }

}  // namespace

// ---------------------------------------------------------------- flat

FlatGroundCostFunction::FlatGroundCostFunction(double segment_start_s, double inv_dt,
                                               double scan_time_s,
                                               const Eigen::Vector3d& normal_lidar,
                                               const Eigen::Matrix3d& sqrt_information)
    : time_in_segment_s_(scan_time_s - segment_start_s),
      inv_dt_(inv_dt),
      normal_lidar_(normal_lidar),
      sqrt_information_(sqrt_information) {}

bool FlatGroundCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                      double** jacobians) const {
  const double u = (time_in_segment_s_ + parameters[6][0]) * inv_dt_;
  bool knot_jacobians, tau_jacobian;
  const int outputs = SplineOutputs(jacobians, &knot_jacobians, &tau_jacobian);
  spline::So3SplineSample s;
  spline::EvaluateSo3Spline(parameters, u, inv_dt_, outputs, &s);

  const Eigen::Map<const Eigen::Vector3d> gravity_dir(parameters[4]);
  const Eigen::Map<const Eigen::Quaterniond> q_bl(parameters[5]);
  const Eigen::Matrix3d c_bl = q_bl.toRotationMatrix();
  const Eigen::Matrix3d c_ab_t = s.rotation.transpose();
  const Eigen::Vector3d up_b = -(c_ab_t * gravity_dir);  // g~_b
  const Eigen::Matrix3d c_lb = c_bl.transpose();
  const Eigen::Vector3d up_l = c_lb * up_b;  // C_bl^T g~_b

  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = sqrt_information_ * (normal_lidar_ - up_l);

  if (jacobians == nullptr) return true;
  // W C_bl^T, shared by the knot, gravity and tau Jacobians.
  const Eigen::Matrix3d w_c_lb = sqrt_information_ * c_lb;
  if (knot_jacobians) {
    const Eigen::Matrix3d d_r_d_eps = -w_c_lb * geometry::Hat(up_b);
    for (int i = 0; i < 4; ++i) {
      if (jacobians[i] == nullptr) continue;
      const Eigen::Matrix3d jt = d_r_d_eps * s.rotation_jacobian[i];
      WriteQuaternionJacobian<3>(jt, parameters[i], jacobians[i]);
    }
  }
  if (jacobians[4] != nullptr) WriteJacobian<3, 3>(w_c_lb * c_ab_t, jacobians[4]);
  if (jacobians[5] != nullptr) {
    const Eigen::Matrix3d jt = -sqrt_information_ * geometry::Hat(up_l);
    WriteQuaternionJacobian<3>(jt, parameters[5], jacobians[5]);
  }
  if (tau_jacobian) {
    Eigen::Map<Eigen::Vector3d> j(jacobians[6]);
    j = -w_c_lb * up_b.cross(s.angular_velocity);
  }
  return true;
}

// ---------------------------------------------------------------- dist

DistanceCostFunction::DistanceCostFunction(const Eigen::Vector3d& normal_lidar,
                                           double lidar_height_m, double imu_height_m,
                                           double sqrt_information)
    : normal_lidar_(normal_lidar),
      height_difference_m_(lidar_height_m - imu_height_m),
      sqrt_information_(sqrt_information) {}

bool DistanceCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> q_bl(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> r_b_lb(parameters[1]);
  const Eigen::Matrix3d c_bl = q_bl.toRotationMatrix();
  const Eigen::Vector3d r_l = c_bl.transpose() * r_b_lb;  // C_bl^T r_b^{lb}
  residuals[0] = sqrt_information_ * (height_difference_m_ - normal_lidar_.dot(r_l));

  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) {
    const Eigen::Matrix<double, 1, 3> jt =
        -sqrt_information_ * normal_lidar_.transpose() * geometry::Hat(r_l);
    WriteQuaternionJacobian<1>(jt, parameters[0], jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    WriteJacobian<1, 3>(-sqrt_information_ * (c_bl * normal_lidar_).transpose(), jacobians[1]);
  }
  return true;
}

// ---------------------------------------------------------------- incl

InclinationCostFunction::InclinationCostFunction(double segment_start_s, double inv_dt,
                                                 double scan_time_s,
                                                 const Eigen::Vector3d& normal_lidar,
                                                 const Eigen::Vector3d& gravity_flat_in_imu,
                                                 double sqrt_information)
    : time_in_segment_s_(scan_time_s - segment_start_s),
      inv_dt_(inv_dt),
      normal_lidar_(normal_lidar),
      up_flat_(UpFromGravity(gravity_flat_in_imu)),
      sqrt_information_(sqrt_information) {}

bool InclinationCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                       double** jacobians) const {
  const double u = (time_in_segment_s_ + parameters[6][0]) * inv_dt_;
  bool knot_jacobians, tau_jacobian;
  const int outputs = SplineOutputs(jacobians, &knot_jacobians, &tau_jacobian);
  spline::So3SplineSample s;
  spline::EvaluateSo3Spline(parameters, u, inv_dt_, outputs, &s);

  const Eigen::Map<const Eigen::Vector3d> gravity_dir(parameters[4]);
  const Eigen::Map<const Eigen::Quaterniond> q_bl(parameters[5]);
  const Eigen::Matrix3d c_bl = q_bl.toRotationMatrix();
  const Eigen::Matrix3d c_ab_t = s.rotation.transpose();
  const Eigen::Vector3d up_b = -(c_ab_t * gravity_dir);        // g~_b
  const Eigen::Vector3d m = up_flat_ - c_bl * normal_lidar_;  // g~_f - C_bl n_l
  residuals[0] = sqrt_information_ * up_b.dot(m);

  if (jacobians == nullptr) return true;
  const Eigen::RowVector3d w_m = sqrt_information_ * m.transpose();
  if (knot_jacobians) {
    const Eigen::RowVector3d d_r_d_eps = w_m * geometry::Hat(up_b);
    for (int i = 0; i < 4; ++i) {
      if (jacobians[i] == nullptr) continue;
      const Eigen::Matrix<double, 1, 3> jt = d_r_d_eps * s.rotation_jacobian[i];
      WriteQuaternionJacobian<1>(jt, parameters[i], jacobians[i]);
    }
  }
  if (jacobians[4] != nullptr) WriteJacobian<1, 3>(-w_m * c_ab_t, jacobians[4]);
  if (jacobians[5] != nullptr) {
    const Eigen::Matrix<double, 1, 3> jt =
        sqrt_information_ * up_b.transpose() * c_bl * geometry::Hat(normal_lidar_);
    WriteQuaternionJacobian<1>(jt, parameters[5], jacobians[5]);
  }
  if (tau_jacobian) jacobians[6][0] = w_m.dot(up_b.cross(s.angular_velocity));
  return true;
}

// ---------------------------------------------------------------- up

UpCostFunction::UpCostFunction(const Eigen::Vector3d& normal_lidar,
                               const Eigen::Vector3d& gravity_flat_in_imu,
                               const Eigen::Matrix3d& sqrt_information)
    : normal_lidar_(normal_lidar),
      up_flat_(UpFromGravity(gravity_flat_in_imu)),
      sqrt_information_(sqrt_information) {}

bool UpCostFunction::Evaluate(double const* const* parameters, double* residuals,
                              double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> q_bl(parameters[0]);
  const Eigen::Vector3d up_flat_l = q_bl.toRotationMatrix().transpose() * up_flat_;  // C_bl^T g~_f
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = sqrt_information_ * (normal_lidar_ - up_flat_l);

  if (jacobians == nullptr || jacobians[0] == nullptr) return true;
  const Eigen::Matrix3d jt = -sqrt_information_ * geometry::Hat(up_flat_l);
  WriteQuaternionJacobian<3>(jt, parameters[0], jacobians[0]);
  return true;
}

}  // namespace tiltcal::calibrate
