#ifndef TILTCAL_COMMON_SPLINE_R3_SPLINE_H_
#define TILTCAL_COMMON_SPLINE_R3_SPLINE_H_

// One segment of the uniform cubic B-spline on R^3 (ordinary basis):
//   p(t) = sum_j b_j(u) p_{s+j},  p' = sum_j b'_j p_{s+j},  p'' = sum_j b''_j p_{s+j}
// p(t) is r_a^{ba}(t) (IMU position in the world frame a, m). Knots are 3
// doubles each. The Jacobians are scalars times the identity:
//   d p^{(n)}(t) / d p_{s+j} = (d^n b_j / dt^n) I,
// so the basis itself (sample.basis) is the Jacobian. Time derivative of
// p^{(n)} is p^{(n+1)} (jerk included for the time derivative of p'').

#include <Eigen/Core>

#include "common/spline/cubic_basis.h"

namespace tiltcal::spline {

struct R3SplineSample {
  Eigen::Vector3d position;      // m
  Eigen::Vector3d velocity;      // m/s
  Eigen::Vector3d acceleration;  // m/s^2
  Eigen::Vector3d jerk;          // m/s^3
  CubicBasis basis;              // b_j and its time derivatives
};

// knots[j] points to the 3 doubles of knot s + j.
inline void EvaluateR3Spline(const double* const knots[4], double u, double inv_dt,
                             R3SplineSample* sample) {
  sample->basis = UniformCubicBasis(u, inv_dt);
  const CubicBasis& b = sample->basis;
  sample->position.setZero();
  sample->velocity.setZero();
  sample->acceleration.setZero();
  sample->jerk.setZero();
  for (int j = 0; j < 4; ++j) {
    const Eigen::Map<const Eigen::Vector3d> p(knots[j]);
    sample->position += b.value[j] * p;
    sample->velocity += b.d1[j] * p;
    sample->acceleration += b.d2[j] * p;
    sample->jerk += b.d3[j] * p;
  }
}

}  // namespace tiltcal::spline

#endif  // TILTCAL_COMMON_SPLINE_R3_SPLINE_H_
