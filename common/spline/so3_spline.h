#ifndef TILTCAL_COMMON_SPLINE_SO3_SPLINE_H_
#define TILTCAL_COMMON_SPLINE_SO3_SPLINE_H_

// One segment of the uniform cumulative cubic B-spline on SO(3):
//
//   R(t) = R_s Exp(lambda_1(u) d_1) Exp(lambda_2(u) d_2) Exp(lambda_3(u) d_3),
//   d_j  = Log(R_{s+j-1}^T R_{s+j}),
//
// with the cumulative basis of cubic_basis.h. R(t) is C_ab(t) (IMU body b to
// world a). Derivatives by the recursions of Sommer et al. (CVPR 2020):
//   w^0 = 0,  w^j = A_j w^{j-1} + lambda'_j d_j,            A_j = Exp(-lambda_j d_j)
//   a^0 = 0,  a^j = A_j a^{j-1} + lambda''_j d_j + w^j x (lambda'_j d_j)
// giving the body angular velocity omega = w^3 (rad/s, dR/dt = R [omega]_x)
// and body angular acceleration alpha = a^3 (rad/s^2).
//
// Knots are unit quaternions stored as 4 doubles (x, y, z, w) (Eigen order).
//
// Jacobians use right perturbations everywhere: knot i <- knot_i Exp(delta_i)
// and R(t) <- R(t) Exp(eps):
//   rotation_jacobian[i]         = d eps   / d delta_i   (3x3)
//   angular_velocity_jacobian[i] = d omega / d delta_i   (3x3)
// Time derivatives: d eps/dt = omega, d omega/dt = alpha.
//
// No heap allocation; all fixed-size Eigen types.

#include <array>

#include <Eigen/Core>

namespace tiltcal::spline {

// Bit flags selecting what EvaluateSo3Spline computes.
enum So3SplineOutput : int {
  kSo3Rotation = 1 << 0,
  kSo3AngularVelocity = 1 << 1,
  kSo3AngularAcceleration = 1 << 2,
  kSo3RotationJacobian = 1 << 3,
  kSo3AngularVelocityJacobian = 1 << 4,
};

struct So3SplineSample {
  Eigen::Matrix3d rotation;              // C_ab(t)
  Eigen::Vector3d angular_velocity;      // omega_b(t), body frame, rad/s
  Eigen::Vector3d angular_acceleration;  // alpha_b(t), body frame, rad/s^2
  std::array<Eigen::Matrix3d, 4> rotation_jacobian;
  std::array<Eigen::Matrix3d, 4> angular_velocity_jacobian;
};

// knots[i] points to the (x, y, z, w) quaternion of knot s + i. u is the
// normalised time in the segment, inv_dt = 1/dt (1/s). outputs is an OR of
// So3SplineOutput; fields not requested are left untouched. The rotation is
// always computed when any Jacobian is requested.
void EvaluateSo3Spline(const double* const knots[4], double u, double inv_dt, int outputs,
                       So3SplineSample* sample);

}  // namespace tiltcal::spline

#endif  // TILTCAL_COMMON_SPLINE_SO3_SPLINE_H_
