#include "stages/calibrate/report/marginal_covariance.h"

#include <string>

#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>

#include "common/linear_algebra/dense_decompositions.h"
#include "stages/calibrate/report/unit_diagonal.h"

namespace tiltcal::calibrate {

Status MarginalCovarianceOfLastColumns(
    const Eigen::SparseMatrix<double, Eigen::RowMajor>& weighted_jacobian, int k,
    double min_relative_pivot, Eigen::MatrixXd* covariance) {
  const int n = static_cast<int>(weighted_jacobian.cols());
  const int rest = n - k;
  if (k <= 0 || rest < 0) {
    return Status::Error("covariance: no parameters to compute the covariance of");
  }
  // H = J^T J, both triangles, column-major.
  const Eigen::SparseMatrix<double> jacobian = weighted_jacobian;
  Eigen::SparseMatrix<double> h = jacobian.transpose() * jacobian;

  // S H S with S = diag(H)^{-1/2}: unit diagonal.
  Eigen::VectorXd scale;
  if (const int c = UnitDiagonalScale(h, &scale); c >= 0) {
    return Status::Error("covariance: the Jacobian is rank deficient (parameter " + std::to_string(c) +
                         " of " + std::to_string(n) + " has no residual)");
  }
  for (int c = 0; c < n; ++c) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(h, c); it; ++it) {
      it.valueRef() *= scale[it.row()] * scale[c];
    }
  }

  // Schur complement onto the last k: C - B^T A^{-1} B (scaled).
  Eigen::MatrixXd schur = Eigen::MatrixXd(h.bottomRightCorner(k, k));
  if (rest > 0) {
    const Eigen::SparseMatrix<double> a = h.topLeftCorner(rest, rest);
    const Eigen::MatrixXd b = Eigen::MatrixXd(h.topRightCorner(rest, k));
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt(a);
    if (ldlt.info() != Eigen::Success) {
      return Status::Error("covariance: the factorisation of the Jacobian's normal matrix failed");
    }
    const double min_pivot = ldlt.vectorD().minCoeff();
    if (!(min_pivot > min_relative_pivot)) {
      return Status::Error("covariance: the Jacobian is rank deficient (a pivot of " +
                           std::to_string(min_pivot) +
                           " of the unit-diagonal normal matrix: the trajectory, gravity or the "
                           "biases are not determined by the data)");
    }
    const Eigen::MatrixXd a_inv_b = ldlt.solve(b);
    schur -= b.transpose() * a_inv_b;
  }
  schur = 0.5 * (schur + schur.transpose());
  const linear_algebra::SymmetricEigen eig = linear_algebra::DecomposeSymmetric(schur);
  if (!eig.converged || !(eig.values[0] > min_relative_pivot)) {
    return Status::Error("covariance: the Jacobian is rank deficient (the extrinsic and time offset: "
                         "smallest eigenvalue " +
                         std::to_string(eig.values[0]) +
                         " of the unit-diagonal marginal information)");
  }
  const Eigen::MatrixXd inverse =
      eig.vectors * eig.values.cwiseInverse().asDiagonal() * eig.vectors.transpose();
  const Eigen::VectorXd last_scale = scale.tail(k);
  *covariance = last_scale.asDiagonal() * inverse * last_scale.asDiagonal();
  return Status::Ok();
}

}  // namespace tiltcal::calibrate
