#ifndef TILTCAL_COMMON_SPLINE_QUATERNION_MANIFOLD_H_
#define TILTCAL_COMMON_SPLINE_QUATERNION_MANIFOLD_H_

// Right-perturbation unit-quaternion manifold for Ceres 2.1.
//
// Storage: 4 doubles (x, y, z, w) — Eigen::Quaterniond's coefficient order
// (NOT ceres::QuaternionManifold's w, x, y, z). Tangent: a rotation vector
// delta (rad) in the BODY frame of the quaternion:
//   Plus(q, delta)  = q * Exp(delta)          (normalised)
//   Minus(y, q)     = Log(q^{-1} * y)
//   PlusJacobian(q) = 0.5 [w I + [v]_x ; -v^T]     (4x3, row-major in Ceres)
//   MinusJacobian(q)= 2 [w I - [v]_x , -v]          (3x4)
// Ceres' own QuaternionManifold / EigenQuaternionManifold perturb on the LEFT;
// do not mix them with the analytic cost functions of tiltcal.
//
// Analytic cost functions compute tangent Jacobians J_t (m x 3) and hand Ceres
// the ambient Jacobian J_t * MinusJacobian(q) (m x 4), since
// MinusJacobian * PlusJacobian = I gives back exactly J_t after Ceres applies
// PlusJacobian. TangentToAmbientJacobian does that product.

#include <ceres/manifold.h>

#include <Eigen/Core>

namespace tiltcal::spline {

class RightQuaternionManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 4; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// Writes J_t * MinusJacobian(q) into the row-major rows x 4 buffer `ambient`.
// q: (x, y, z, w). jt: rows x 3 tangent Jacobian.
template <int kRows>
inline void TangentToAmbientJacobian(const Eigen::Matrix<double, kRows, 3>& jt, const double* q,
                                     double* ambient) {
  // J_t * 2 [w I - [v]_x , -v]:
  //   left 3 columns: 2 (w J_t - J_t [v]_x), last column: -2 J_t v.
  const double x = q[0], y = q[1], z = q[2], w = q[3];
  for (int r = 0; r < kRows; ++r) {
    const double a = jt(r, 0), b = jt(r, 1), c = jt(r, 2);
    // Row of J_t [v]_x = (a, b, c) [[0,-z,y],[z,0,-x],[-y,x,0]] = (b z - c y, c x - a z, a y - b x).
    double* out = ambient + 4 * r;
    out[0] = 2.0 * (w * a - (b * z - c * y));
    out[1] = 2.0 * (w * b - (c * x - a * z));
    out[2] = 2.0 * (w * c - (a * y - b * x));
    out[3] = -2.0 * (a * x + b * y + c * z);
  }
}

}  // namespace tiltcal::spline

#endif  // TILTCAL_COMMON_SPLINE_QUATERNION_MANIFOLD_H_
