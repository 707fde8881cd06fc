#ifndef TILTCAL_COMMON_GEOMETRY_SO3_H_
#define TILTCAL_COMMON_GEOMETRY_SO3_H_

// SO(3) toolkit: hat operator, exponential and logarithm maps (quaternion and
// rotation-matrix forms), right/left Jacobians and their inverses, and the
// right-perturbation quaternion "box" operations.
//
// Conventions (docs/design.md §5):
// - Rotation vectors phi are in radians; Exp(phi) is the rotation by |phi|
//   about phi/|phi|.
// - Quaternions are Hamilton, unit, and handled as Eigen::Quaternion, whose
//   coefficient storage is (x, y, z, w). Every raw `double[4]` quaternion in
//   tiltcal's optimiser uses this (x, y, z, w) storage order; the on-disk proto
//   Quaternion spells its fields {w x y z} and is converted by name.
// - Perturbations are RIGHT (body-frame): R <- R Exp(delta). The right Jacobian
//   Jr satisfies Exp(phi + dphi) ~= Exp(phi) Exp(Jr(phi) dphi), the left one
//   Jl(phi) = Jr(-phi) = Jr(phi)^T satisfies Exp(phi + dphi) ~= Exp(Jl dphi) Exp(phi).
//
// Hat, ExpQuaternion and LogQuaternion are templates so that test-only
// autodiff twins can run them on ceres::Jet; their small-angle branches test
// the squared norm so no sqrt(0) is ever differentiated. Everything else is
// double-only and defined in so3.cc.

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tiltcal::geometry {

// [v]_x, the skew-symmetric matrix with [v]_x w = v x w.
template <typename T>
Eigen::Matrix<T, 3, 3> Hat(const Eigen::Matrix<T, 3, 1>& v) {
  Eigen::Matrix<T, 3, 3> m;
  m << T(0), -v.z(), v.y(),  //
      v.z(), T(0), -v.x(),   //
      -v.y(), v.x(), T(0);
  return m;
}

// Exp: rotation vector (rad) -> unit quaternion.
// q = [sin(theta/2) / theta * phi, cos(theta/2)], Taylor series below 1e-4 rad.
template <typename T>
Eigen::Quaternion<T> ExpQuaternion(const Eigen::Matrix<T, 3, 1>& phi) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta_sq = phi.squaredNorm();
  T scale;  // sin(theta/2) / theta
  T w;      // cos(theta/2)
  if (theta_sq < T(1e-8)) {
    scale = T(0.5) - theta_sq / T(48.0) + theta_sq * theta_sq / T(3840.0);
    w = T(1.0) - theta_sq / T(8.0) + theta_sq * theta_sq / T(384.0);
  } else {
    const T theta = sqrt(theta_sq);
    const T half = T(0.5) * theta;
    scale = sin(half) / theta;
    w = cos(half);
  }
  return Eigen::Quaternion<T>(w, scale * phi.x(), scale * phi.y(), scale * phi.z());
}

// Log: unit quaternion -> rotation vector with |phi| <= pi. Uses the shortest
// representative (q and -q are the same rotation) and atan2, so it is accurate
// near 0 and near pi. Invariant to the scale of q (a non-unit q is treated as
// q / |q|).
template <typename T>
Eigen::Matrix<T, 3, 1> LogQuaternion(const Eigen::Quaternion<T>& q_in) {
  using std::atan2;
  using std::sqrt;
  T w = q_in.w();
  Eigen::Matrix<T, 3, 1> v = q_in.vec();
  if (w < T(0)) {
    w = -w;
    v = -v;
  }
  const T n_sq = v.squaredNorm();
  T scale;  // 2 atan2(n, w) / n
  if (n_sq < T(1e-16) * w * w) {
    // atan(x)/x = 1 - x^2/3 + ..., x = n/w  (|x| < 1e-8: next term negligible).
    scale = T(2.0) / w * (T(1.0) - n_sq / (T(3.0) * w * w));
  } else {
    const T n = sqrt(n_sq);
    scale = T(2.0) * atan2(n, w) / n;
  }
  return scale * v;
}

// Exp: rotation vector -> rotation matrix (Rodrigues).
Eigen::Matrix3d ExpMatrix(const Eigen::Vector3d& phi);

// Log: rotation matrix -> rotation vector (|phi| <= pi). Goes through a
// quaternion (Eigen's trace-branching conversion), robust near 0 and pi.
Eigen::Vector3d LogMatrix(const Eigen::Matrix3d& rotation);

// Right Jacobian of SO(3):
//   Jr(phi) = I - (1 - cos t)/t^2 [phi]_x + (t - sin t)/t^3 [phi]_x^2,  t = |phi|.
Eigen::Matrix3d RightJacobian(const Eigen::Vector3d& phi);
// Jr(phi)^{-1} = I + 1/2 [phi]_x + (1/t^2 - cot(t/2)/(2t)) [phi]_x^2, valid for t < 2 pi.
Eigen::Matrix3d RightJacobianInverse(const Eigen::Vector3d& phi);
// Jl(phi) = Jr(-phi) = Jr(phi)^T and its inverse.
inline Eigen::Matrix3d LeftJacobian(const Eigen::Vector3d& phi) { return RightJacobian(-phi); }
inline Eigen::Matrix3d LeftJacobianInverse(const Eigen::Vector3d& phi) {
  return RightJacobianInverse(-phi);
}

// Exp(phi) as a rotation matrix together with Jr(phi): one trigonometric
// evaluation for both (the spline needs them together).
void ExpMatrixAndRightJacobian(const Eigen::Vector3d& phi, Eigen::Matrix3d* exp,
                               Eigen::Matrix3d* right_jacobian);

// Right-perturbation box operations on unit quaternions:
//   BoxPlus(q, delta) = q * Exp(delta),  BoxMinus(q1, q0) = Log(q0^{-1} q1),
// so BoxPlus(q0, BoxMinus(q1, q0)) represents the same rotation as q1.
inline Eigen::Quaterniond BoxPlus(const Eigen::Quaterniond& q, const Eigen::Vector3d& delta) {
  return (q * ExpQuaternion(delta)).normalized();
}
inline Eigen::Vector3d BoxMinus(const Eigen::Quaterniond& q1, const Eigen::Quaterniond& q0) {
  return LogQuaternion(Eigen::Quaterniond(q0.conjugate() * q1));
}

// d(q * Exp(delta))/d(delta) at delta = 0 for a unit quaternion q, as a 4x3
// matrix whose rows follow the (x, y, z, w) storage:  0.5 [w I + [v]_x ; -v^T].
Eigen::Matrix<double, 4, 3> QuaternionPlusJacobian(const Eigen::Quaterniond& q);
// d Log(q^{-1} y)/dy at y = q, 3x4 over (x, y, z, w):  2 [w I - [v]_x , -v].
// Equals 4 PlusJacobian^T, and MinusJacobian * PlusJacobian = I.
Eigen::Matrix<double, 3, 4> QuaternionMinusJacobian(const Eigen::Quaterniond& q);

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_SO3_H_
