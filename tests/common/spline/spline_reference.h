#ifndef TILTCAL_TESTS_COMMON_SPLINE_SPLINE_REFERENCE_H_
#define TILTCAL_TESTS_COMMON_SPLINE_SPLINE_REFERENCE_H_

// Test-only reference implementation of the split cubic B-spline, templated
// so it runs on ceres::Jet (autodiff twins of the analytic code). It is
// deliberately written differently from common/spline:
// - the basis comes from the blending matrix times the power vector;
// - the rotation is a product of unit quaternions;
// - omega and alpha come from the product rule on the quaternion factors
//   (Lovegrove et al.), not from the Sommer recursion:
//     F_j = Exp(lambda_j d_j),  dF_j/dt = F_j xi_j,  xi_j = [lambda'_j d_j / 2, 0],
//     omega = 2 vec(q^* q'),  alpha = 2 vec(q^* q'').
// Quaternions are Eigen (storage x, y, z, w), as everywhere in tiltcal.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/geometry/so3.h"

namespace tiltcal::testing {

template <typename T>
struct ReferenceBasis {
  T lambda[4], lambda_d1[4], lambda_d2[4];  // cumulative, d/dt, d^2/dt^2
  T b[4], b_d1[4], b_d2[4];                  // ordinary
};

template <typename T>
ReferenceBasis<T> MakeReferenceBasis(const T& u, double inv_dt) {
  // Ordinary blending matrix, rows j, columns powers u^0..u^3, times 1/6.
  static const double kM[4][4] = {{1, -3, 3, -1}, {4, 0, -6, 3}, {1, 3, 3, -3}, {0, 0, 0, 1}};
  const T p[4] = {T(1.0), u, u * u, u * u * u};
  const T p1[4] = {T(0.0), T(1.0), T(2.0) * u, T(3.0) * u * u};
  const T p2[4] = {T(0.0), T(0.0), T(2.0), T(6.0) * u};
  ReferenceBasis<T> r;
  for (int j = 0; j < 4; ++j) {
    r.b[j] = r.b_d1[j] = r.b_d2[j] = T(0.0);
    for (int k = 0; k < 4; ++k) {
      r.b[j] += kM[j][k] / 6.0 * p[k];
      r.b_d1[j] += kM[j][k] / 6.0 * p1[k] * inv_dt;
      r.b_d2[j] += kM[j][k] / 6.0 * p2[k] * inv_dt * inv_dt;
    }
  }
  for (int j = 0; j < 4; ++j) {
    r.lambda[j] = r.lambda_d1[j] = r.lambda_d2[j] = T(0.0);
    for (int i = j; i < 4; ++i) {
      r.lambda[j] += r.b[i];
      r.lambda_d1[j] += r.b_d1[i];
      r.lambda_d2[j] += r.b_d2[i];
    }
  }
  return r;
}

template <typename T>
struct ReferenceSo3Sample {
  Eigen::Quaternion<T> q;
  Eigen::Matrix<T, 3, 1> omega;
  Eigen::Matrix<T, 3, 1> alpha;
};

template <typename T>
Eigen::Quaternion<T> PureQuaternion(const Eigen::Matrix<T, 3, 1>& v) {
  return Eigen::Quaternion<T>(T(0.0), v.x(), v.y(), v.z());
}

// knots: 4 quaternions (need not be exactly unit; they are normalised).
template <typename T>
ReferenceSo3Sample<T> ReferenceSo3(const Eigen::Quaternion<T> knots_in[4], const T& u,
                                   double inv_dt) {
  const ReferenceBasis<T> basis = MakeReferenceBasis(u, inv_dt);
  Eigen::Quaternion<T> knots[4];
  for (int j = 0; j < 4; ++j) knots[j] = knots_in[j].normalized();
  Eigen::Quaternion<T> f[4], xi[4], xi_dot[4];
  f[0] = knots[0];
  xi[0] = xi_dot[0] = Eigen::Quaternion<T>(T(0.0), T(0.0), T(0.0), T(0.0));
  for (int j = 1; j < 4; ++j) {
    const Eigen::Matrix<T, 3, 1> d =
        geometry::LogQuaternion(Eigen::Quaternion<T>(knots[j - 1].conjugate() * knots[j]));
    f[j] = geometry::ExpQuaternion(Eigen::Matrix<T, 3, 1>(basis.lambda[j] * d));
    xi[j] = PureQuaternion(Eigen::Matrix<T, 3, 1>(T(0.5) * basis.lambda_d1[j] * d));
    xi_dot[j] = PureQuaternion(Eigen::Matrix<T, 3, 1>(T(0.5) * basis.lambda_d2[j] * d));
  }
  // f_0 (f_1 m_1) (f_2 m_2) (f_3 m_3): the product with factor j replaced by
  // f_j m_j (m_j = 1, xi_j or xi_j^2 + xi'_j).
  auto product = [&](const Eigen::Quaternion<T>* m) {
    Eigen::Quaternion<T> acc = f[0];
    for (int j = 1; j < 4; ++j) acc = acc * (f[j] * m[j]);
    return acc;
  };
  const Eigen::Quaternion<T> one(T(1.0), T(0.0), T(0.0), T(0.0));
  Eigen::Quaternion<T> m[4] = {one, one, one, one};
  ReferenceSo3Sample<T> out;
  out.q = product(m);

  Eigen::Matrix<T, 4, 1> q_dot = Eigen::Matrix<T, 4, 1>::Zero();
  Eigen::Matrix<T, 4, 1> q_ddot = Eigen::Matrix<T, 4, 1>::Zero();
  for (int j = 1; j < 4; ++j) {
    m[j] = xi[j];
    q_dot += product(m).coeffs();
    m[j] = Eigen::Quaternion<T>((xi[j] * xi[j]).coeffs() + xi_dot[j].coeffs());
    q_ddot += product(m).coeffs();
    m[j] = one;
    for (int i = j + 1; i < 4; ++i) {
      m[j] = xi[j];
      m[i] = xi[i];
      q_ddot += T(2.0) * product(m).coeffs();
      m[j] = one;
      m[i] = one;
    }
  }
  const Eigen::Quaternion<T> conj = out.q.conjugate();
  out.omega = T(2.0) * (conj * Eigen::Quaternion<T>(q_dot)).vec();
  out.alpha = T(2.0) * (conj * Eigen::Quaternion<T>(q_ddot)).vec();
  return out;
}

// The same quantities by the Sommer et al. recursion (the formula the
// analytic code differentiates), on Jets: the benchmark's autodiff anchor, so
// that "analytic vs autodiff" compares the same mathematics.
template <typename T>
ReferenceSo3Sample<T> SommerSo3(const Eigen::Quaternion<T> knots[4], const T& u, double inv_dt) {
  const ReferenceBasis<T> basis = MakeReferenceBasis(u, inv_dt);
  ReferenceSo3Sample<T> out;
  out.q = knots[0].normalized();
  out.omega.setZero();
  out.alpha.setZero();
  for (int j = 1; j < 4; ++j) {
    const Eigen::Matrix<T, 3, 1> d =
        geometry::LogQuaternion(Eigen::Quaternion<T>(knots[j - 1].conjugate() * knots[j]));
    const Eigen::Quaternion<T> e = geometry::ExpQuaternion(Eigen::Matrix<T, 3, 1>(basis.lambda[j] * d));
    out.q = out.q * e;
    const Eigen::Matrix<T, 3, 1> vd = basis.lambda_d1[j] * d;
    const Eigen::Quaternion<T> e_inv = e.conjugate();
    out.omega = e_inv * out.omega + vd;
    out.alpha = e_inv * out.alpha + basis.lambda_d2[j] * d + out.omega.cross(vd);
  }
  return out;
}

template <typename T>
struct ReferenceR3Sample {
  Eigen::Matrix<T, 3, 1> position, velocity, acceleration;
};

template <typename T>
ReferenceR3Sample<T> ReferenceR3(const Eigen::Matrix<T, 3, 1> knots[4], const T& u,
                                 double inv_dt) {
  const ReferenceBasis<T> basis = MakeReferenceBasis(u, inv_dt);
  ReferenceR3Sample<T> out;
  out.position.setZero();
  out.velocity.setZero();
  out.acceleration.setZero();
  for (int j = 0; j < 4; ++j) {
    out.position += basis.b[j] * knots[j];
    out.velocity += basis.b_d1[j] * knots[j];
    out.acceleration += basis.b_d2[j] * knots[j];
  }
  return out;
}

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_COMMON_SPLINE_SPLINE_REFERENCE_H_
