#ifndef TILTCAL_TESTS_TESTING_COST_FUNCTION_TWINS_H_
#define TILTCAL_TESTS_TESTING_COST_FUNCTION_TWINS_H_

// Autodiff twins of the analytic residuals in stages/calibrate, for tests and
// the benchmark anchor ONLY (never used in production). They evaluate the
// same formulas through the templated reference spline
// (tests/common/spline/spline_reference.h) on ceres::Jet: kSommer = false
// (the aliases GyroTwin, AccelTwin, PointToPlaneTwin used by the tests) takes
// the independent quaternion product-rule derivatives; kSommer = true (the
// benchmark anchor) the Sommer recursion, i.e. the analytic code's formulas. Parameter blocks,
// order and storage are identical to the analytic cost functions; quaternions
// are (x, y, z, w) with the right-perturbation manifold.

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "tests/common/spline/spline_reference.h"

namespace tiltcal::testing {

template <bool kSommer, typename T>
ReferenceSo3Sample<T> EvaluateSo3(const Eigen::Quaternion<T> knots[4], const T& u, double inv_dt) {
  if constexpr (kSommer) {
    return SommerSo3<T>(knots, u, inv_dt);
  } else {
    return ReferenceSo3<T>(knots, u, inv_dt);
  }
}

template <typename T>
void LoadQuaternions(const T* const q0, const T* const q1, const T* const q2, const T* const q3,
                     Eigen::Quaternion<T> out[4]) {
  const T* const ptr[4] = {q0, q1, q2, q3};
  for (int i = 0; i < 4; ++i) out[i] = Eigen::Map<const Eigen::Quaternion<T>>(ptr[i]);
}

template <typename T>
void LoadVectors(const T* const p0, const T* const p1, const T* const p2, const T* const p3,
                 Eigen::Matrix<T, 3, 1> out[4]) {
  const T* const ptr[4] = {p0, p1, p2, p3};
  for (int i = 0; i < 4; ++i) out[i] = Eigen::Map<const Eigen::Matrix<T, 3, 1>>(ptr[i]);
}

// The reading of an imperfect triad, (I + E) v, E 3x3 row-major.
template <typename T>
Eigen::Matrix<T, 3, 1> TriadReading(const T* const e, const Eigen::Matrix<T, 3, 1>& v) {
  Eigen::Matrix<T, 3, 1> out;
  for (int r = 0; r < 3; ++r) out[r] = v[r] + e[3 * r] * v[0] + e[3 * r + 1] * v[1] + e[3 * r + 2] * v[2];
  return out;
}

// r = ((I + E_g) omega_b(t) + b_g - omega_m) / sigma.
template <bool kSommer>
struct GyroTwinT {
  double u, inv_dt, sigma;
  Eigen::Vector3d measured;
  template <typename T>
  bool operator()(const T* const q0, const T* const q1, const T* const q2, const T* const q3,
                  const T* const bias, const T* const errors, T* residual) const {
    Eigen::Quaternion<T> q[4];
    LoadQuaternions(q0, q1, q2, q3, q);
    const auto s = EvaluateSo3<kSommer>(q, T(u), inv_dt);
    const Eigen::Matrix<T, 3, 1> omega = TriadReading(errors, Eigen::Matrix<T, 3, 1>(s.omega));
    for (int r = 0; r < 3; ++r) residual[r] = (omega[r] + bias[r] - T(measured[r])) / sigma;
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<GyroTwinT, 3, 4, 4, 4, 4, 3, 9>;
};

// r = ((I + E_a) C^T (p'' - g_norm n_g) + b_a - f_m) / sigma.
template <bool kSommer>
struct AccelTwinT {
  double u, inv_dt, sigma, gravity_norm;
  Eigen::Vector3d measured;
  template <typename T>
  bool operator()(const T* const q0, const T* const q1, const T* const q2, const T* const q3,
                  const T* const p0, const T* const p1, const T* const p2, const T* const p3,
                  const T* const gravity_dir, const T* const bias, const T* const errors,
                  T* residual) const {
    Eigen::Quaternion<T> q[4];
    Eigen::Matrix<T, 3, 1> p[4];
    LoadQuaternions(q0, q1, q2, q3, q);
    LoadVectors(p0, p1, p2, p3, p);
    const auto s = EvaluateSo3<kSommer>(q, T(u), inv_dt);
    const auto ps = ReferenceR3<T>(p, T(u), inv_dt);
    const Eigen::Matrix<T, 3, 1> g = Eigen::Map<const Eigen::Matrix<T, 3, 1>>(gravity_dir) * T(gravity_norm);
    const Eigen::Matrix<T, 3, 1> f = s.q.conjugate() * (ps.acceleration - g);
    const Eigen::Matrix<T, 3, 1> reading = TriadReading(errors, f);
    for (int r = 0; r < 3; ++r) residual[r] = (reading[r] + bias[r] - T(measured[r])) / sigma;
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<AccelTwinT, 3, 4, 4, 4, 4, 3, 3, 3, 3, 3, 3, 9>;
};

// p_a = C(t_j + tau) (C_bl p_l + r_b) + r_a(t_j + tau), frozen segment,
// r = (n^T p_a + d) / sigma.
template <bool kSommer>
struct PointToPlaneTwinT {
  double time_in_segment_s, inv_dt, sigma, offset;
  Eigen::Vector3d point, normal;
  template <typename T>
  bool operator()(const T* const q0, const T* const q1, const T* const q2, const T* const q3,
                  const T* const p0, const T* const p1, const T* const p2, const T* const p3,
                  const T* const q_bl_ptr, const T* const r_b_ptr, const T* const tau,
                  T* residual) const {
    Eigen::Quaternion<T> q[4];
    Eigen::Matrix<T, 3, 1> p[4];
    LoadQuaternions(q0, q1, q2, q3, q);
    LoadVectors(p0, p1, p2, p3, p);
    const T u = (T(time_in_segment_s) + tau[0]) * inv_dt;
    const auto s = EvaluateSo3<kSommer>(q, u, inv_dt);
    const auto ps = ReferenceR3<T>(p, u, inv_dt);
    const Eigen::Quaternion<T> q_bl = Eigen::Map<const Eigen::Quaternion<T>>(q_bl_ptr).normalized();
    const Eigen::Matrix<T, 3, 1> x_b =
        q_bl * point.cast<T>() + Eigen::Map<const Eigen::Matrix<T, 3, 1>>(r_b_ptr);
    const Eigen::Matrix<T, 3, 1> p_a = s.q * x_b + ps.position;
    residual[0] = (normal.cast<T>().dot(p_a) + T(offset)) / sigma;
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<PointToPlaneTwinT, 1, 4, 4, 4, 4, 3, 3, 3, 3, 4, 3, 1>;
};

// r = Log(C_m^T C(t)) / sigma.
template <bool kSommer>
struct OrientationTwinT {
  double u, inv_dt, sigma;
  Eigen::Quaterniond measured;
  template <typename T>
  bool operator()(const T* const q0, const T* const q1, const T* const q2, const T* const q3,
                  T* residual) const {
    Eigen::Quaternion<T> q[4];
    LoadQuaternions(q0, q1, q2, q3, q);
    const auto s = EvaluateSo3<kSommer>(q, T(u), inv_dt);
    const Eigen::Matrix<T, 3, 1> phi =
        geometry::LogQuaternion<T>(measured.cast<T>().conjugate() * s.q);
    for (int r = 0; r < 3; ++r) residual[r] = phi[r] / sigma;
    return true;
  }
  using AutoDiff = ceres::AutoDiffCostFunction<OrientationTwinT, 3, 4, 4, 4, 4>;
};

using GyroTwin = GyroTwinT<false>;
using OrientationTwin = OrientationTwinT<false>;
using AccelTwin = AccelTwinT<false>;
using PointToPlaneTwin = PointToPlaneTwinT<false>;

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_COST_FUNCTION_TWINS_H_
