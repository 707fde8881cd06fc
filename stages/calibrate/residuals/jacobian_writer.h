#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUALS_JACOBIAN_WRITER_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUALS_JACOBIAN_WRITER_H_

// Small helpers shared by the analytic cost functions of the calibrator:
// writing fixed-size Jacobian blocks into Ceres' row-major buffers.
// Quaternion parameter blocks are (x, y, z, w) with the right-perturbation
// manifold (common/spline/quaternion_manifold.h): a tangent Jacobian J_t is
// written as J_t * MinusJacobian(q).

#include <Eigen/Core>

#include "common/spline/quaternion_manifold.h"

namespace tiltcal::calibrate {

// Row-major storage matching Ceres' Jacobian blocks (a column vector stays
// column-major, which is the same memory layout).
template <int kRows, int kCols>
using RowMajorMatrix =
    Eigen::Matrix<double, kRows, kCols, (kCols == 1 && kRows != 1) ? Eigen::ColMajor : Eigen::RowMajor>;

template <int kRows, int kCols, typename Derived>
inline void WriteJacobian(const Eigen::MatrixBase<Derived>& value, double* jacobian) {
  Eigen::Map<RowMajorMatrix<kRows, kCols>> out(jacobian);
  out = value;
}

// Whether Ceres asked for the Jacobian of any of the four knot blocks
// 0..3 (the first parameter blocks of every spline residual).
inline bool KnotJacobiansRequested(double** jacobians) {
  if (jacobians == nullptr) return false;
  for (int i = 0; i < 4; ++i) {
    if (jacobians[i] != nullptr) return true;
  }
  return false;
}

// Tangent Jacobian (kRows x 3) of a quaternion block q -> ambient kRows x 4.
template <int kRows>
inline void WriteQuaternionJacobian(const Eigen::Matrix<double, kRows, 3>& tangent,
                                    const double* q, double* jacobian) {
  spline::TangentToAmbientJacobian<kRows>(tangent, q, jacobian);
}

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUALS_JACOBIAN_WRITER_H_
