#include "stages/calibrate/residuals/point_to_plane_cost_function.h"

#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "common/spline/cubic_basis.h"
#include "common/spline/so3_spline.h"
#include "stages/calibrate/residuals/jacobian_writer.h"

namespace tiltcal::calibrate {

PointToPlaneCostFunction::PointToPlaneCostFunction(double segment_start_s, double inv_dt,
                                                   double point_time_s,
                                                   const Eigen::Vector3d& point_lidar_m,
                                                   const Eigen::Vector3d& plane_normal_world,
                                                   double plane_offset_m, double sigma_m)
    : time_in_segment_s_(point_time_s - segment_start_s),
      inv_dt_(inv_dt),
      point_lidar_m_(point_lidar_m),
      normal_scaled_(plane_normal_world / sigma_m),
      offset_scaled_(plane_offset_m / sigma_m) {}

bool PointToPlaneCostFunction::Evaluate(double const* const* parameters, double* residuals,
                                        double** jacobians) const {
  const double tau = parameters[10][0];
  const double u = (time_in_segment_s_ + tau) * inv_dt_;

  const bool rotation_jacobians = KnotJacobiansRequested(jacobians);
  const bool tau_jacobian = jacobians != nullptr && jacobians[10] != nullptr;
  spline::So3SplineSample s;
  spline::EvaluateSo3Spline(parameters, u, inv_dt_,
                            spline::kSo3Rotation |
                                (rotation_jacobians ? spline::kSo3RotationJacobian : 0) |
                                (tau_jacobian ? spline::kSo3AngularVelocity : 0),
                            &s);
  const spline::CubicBasis b = spline::UniformCubicBasis(u, inv_dt_);
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  for (int j = 0; j < 4; ++j) {
    const Eigen::Map<const Eigen::Vector3d> p(parameters[4 + j]);
    position += b.value[j] * p;
    velocity += b.d1[j] * p;
  }

  const Eigen::Map<const Eigen::Quaterniond> q_bl(parameters[8]);
  const Eigen::Map<const Eigen::Vector3d> r_b_lb(parameters[9]);
  const Eigen::Matrix3d c_bl = q_bl.toRotationMatrix();
  const Eigen::Vector3d x_b = c_bl * point_lidar_m_ + r_b_lb;  // point in IMU frame
  const Eigen::Vector3d p_a = s.rotation * x_b + position;
  residuals[0] = normal_scaled_.dot(p_a) + offset_scaled_;

  if (jacobians == nullptr) return true;
  // n^T C, the row that maps IMU-frame displacements to the residual.
  const Eigen::RowVector3d n_c = normal_scaled_.transpose() * s.rotation;
  if (rotation_jacobians) {
    // C Exp(eps) x = C x - C [x]_x eps.
    const Eigen::RowVector3d d_r_d_eps = -n_c * geometry::Hat(x_b);
    for (int i = 0; i < 4; ++i) {
      if (jacobians[i] == nullptr) continue;
      const Eigen::Matrix<double, 1, 3> jt = d_r_d_eps * s.rotation_jacobian[i];
      WriteQuaternionJacobian<1>(jt, parameters[i], jacobians[i]);
    }
  }
  for (int j = 0; j < 4; ++j) {
    if (jacobians[4 + j] != nullptr) {
      WriteJacobian<1, 3>(b.value[j] * normal_scaled_.transpose(), jacobians[4 + j]);
    }
  }
  if (jacobians[8] != nullptr) {
    // C_bl Exp(delta) p_l = C_bl p_l - C_bl [p_l]_x delta.
    const Eigen::Matrix<double, 1, 3> jt = -n_c * c_bl * geometry::Hat(point_lidar_m_);
    WriteQuaternionJacobian<1>(jt, parameters[8], jacobians[8]);
  }
  if (jacobians[9] != nullptr) WriteJacobian<1, 3>(n_c, jacobians[9]);
  if (tau_jacobian) {
    // d p_a / dt = C (omega x x_b) + r'_a(t).
    jacobians[10][0] = n_c.dot(s.angular_velocity.cross(x_b)) + normal_scaled_.dot(velocity);
  }
  return true;
}

}  // namespace tiltcal::calibrate
