#ifndef TILTCAL_COMMON_SPLINE_CUBIC_BASIS_H_
#define TILTCAL_COMMON_SPLINE_CUBIC_BASIS_H_

// Blending weights of the uniform cubic B-spline (order 4) on one segment,
// as functions of the normalised time u = (t - t_s)/dt in [0, 1], where t_s
// is the segment start, and their time derivatives (already scaled by
// dt^-1, dt^-2, dt^-3, so they are d/dt, not d/du).
//
// Ordinary basis (R^3 spline, p(t) = sum_j b_j p_{s+j}):
//   b0 = (1-u)^3/6, b1 = (4 - 6u^2 + 3u^3)/6, b2 = (1 + 3u + 3u^2 - 3u^3)/6, b3 = u^3/6.
// Cumulative basis (SO(3) spline, lambda_j = sum_{i>=j} b_i):
//   lambda0 = 1, lambda1 = (5 + 3u - 3u^2 + u^3)/6, lambda2 = (1 + 3u + 3u^2 - 2u^3)/6,
//   lambda3 = u^3/6.
// The polynomials are also evaluated for u slightly outside [0, 1] (the
// segment polynomial extended), which the time-offset residuals rely on.

#include <Eigen/Core>

namespace tiltcal::spline {

struct CubicBasis {
  Eigen::Vector4d value;   // b_j(u)
  Eigen::Vector4d d1;      // d b_j / dt     (1/s)
  Eigen::Vector4d d2;      // d^2 b_j / dt^2 (1/s^2)
  Eigen::Vector4d d3;      // d^3 b_j / dt^3 (1/s^3)
};

// inv_dt = 1/dt in 1/s.
inline CubicBasis UniformCubicBasis(double u, double inv_dt) {
  const double u2 = u * u;
  const double u3 = u2 * u;
  const double v = 1.0 - u;
  const double i2 = inv_dt * inv_dt;
  CubicBasis b;
  b.value << v * v * v / 6.0, (4.0 - 6.0 * u2 + 3.0 * u3) / 6.0,
      (1.0 + 3.0 * u + 3.0 * u2 - 3.0 * u3) / 6.0, u3 / 6.0;
  b.d1 << -0.5 * v * v, 0.5 * (-4.0 * u + 3.0 * u2), 0.5 * (1.0 + 2.0 * u - 3.0 * u2), 0.5 * u2;
  b.d1 *= inv_dt;
  b.d2 << v, 3.0 * u - 2.0, 1.0 - 3.0 * u, u;
  b.d2 *= i2;
  b.d3 << -1.0, 3.0, -3.0, 1.0;
  b.d3 *= i2 * inv_dt;
  return b;
}

// Cumulative basis; entry 0 is the constant 1 (and its derivatives 0).
inline CubicBasis CumulativeCubicBasis(double u, double inv_dt) {
  const double u2 = u * u;
  const double u3 = u2 * u;
  const double v = 1.0 - u;
  const double i2 = inv_dt * inv_dt;
  CubicBasis b;
  b.value << 1.0, (5.0 + 3.0 * u - 3.0 * u2 + u3) / 6.0, (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) / 6.0,
      u3 / 6.0;
  b.d1 << 0.0, 0.5 * v * v, 0.5 * (1.0 + 2.0 * u - 2.0 * u2), 0.5 * u2;
  b.d1 *= inv_dt;
  b.d2 << 0.0, -v, 1.0 - 2.0 * u, u;
  b.d2 *= i2;
  b.d3 << 0.0, 1.0, -2.0, 1.0;
  b.d3 *= i2 * inv_dt;
  return b;
}

}  // namespace tiltcal::spline

#endif  // TILTCAL_COMMON_SPLINE_CUBIC_BASIS_H_
