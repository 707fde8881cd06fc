#include "common/linear_algebra/dense_decompositions.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>

namespace tiltcal::linear_algebra {

Eigen::MatrixXd Inverse(const Eigen::MatrixXd& a) { return a.inverse(); }

Eigen::MatrixXd SolveByLu(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.partialPivLu().solve(b);
}

Eigen::VectorXd SolveByLdlt(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, bool* factorised) {
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(a);
  if (factorised != nullptr) *factorised = ldlt.info() == Eigen::Success;
  return ldlt.solve(b);
}

SymmetricEigen DecomposeSymmetric(const Eigen::MatrixXd& a, EigenvectorsToo vectors) {
  const bool with_vectors = vectors == EigenvectorsToo::kYes;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(
      a, with_vectors ? Eigen::ComputeEigenvectors : Eigen::EigenvaluesOnly);
  SymmetricEigen out;
  out.converged = solver.info() == Eigen::Success;
  out.values = solver.eigenvalues();
  if (with_vectors) out.vectors = solver.eigenvectors();
  return out;
}

RightSingularVectors DecomposeSingular(const Eigen::MatrixXd& a) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a, Eigen::ComputeFullV);
  return {svd.singularValues(), svd.matrixV()};
}

}  // namespace tiltcal::linear_algebra
