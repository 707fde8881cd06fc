#ifndef TILTCAL_COMMON_LINEAR_ALGEBRA_DENSE_DECOMPOSITIONS_H_
#define TILTCAL_COMMON_LINEAR_ALGEBRA_DENSE_DECOMPOSITIONS_H_

// Eigen's decompositions of dynamic-size double matrices (Eigen::MatrixXd),
// instantiated in this library's one translation unit. At -O3 each costs
// every unit that instantiates it 2-6 s of compile; the callers (fusion,
// covariance checks and reports, verification, hand-eye) are small
// matrices (up to 7x7, or 4N x 4) where a call through a library costs
// nothing. Each function computes exactly what the Eigen call it names
// computes.

#include <Eigen/Core>

namespace tiltcal::linear_algebra {

// A^{-1} by LU with partial pivoting (Eigen: a.inverse()). A square and
// invertible; a singular A gives non-finite entries.
Eigen::MatrixXd Inverse(const Eigen::MatrixXd& a);

// X with A X = B by LU with partial pivoting (Eigen: a.partialPivLu().solve(b)).
Eigen::MatrixXd SolveByLu(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

// x with A x = b by the LDLT factorisation (robust Cholesky with pivoting)
// of the symmetric A, read from its lower triangle (Eigen: a.ldlt().solve(b)).
// *factorised, when given: false when the factorisation failed
// (Eigen::NumericalIssue), and then x is not a solution.
Eigen::VectorXd SolveByLdlt(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                            bool* factorised = nullptr);

// The eigen-decomposition A = V diag(values) V^T of a symmetric A, read from
// its lower triangle (Eigen::SelfAdjointEigenSolver).
struct SymmetricEigen {
  bool converged = false;   // false: the QR iteration did not converge
  Eigen::VectorXd values;   // ascending
  Eigen::MatrixXd vectors;  // unit eigenvectors as columns; empty when not asked for
};
enum class EigenvectorsToo { kNo, kYes };
SymmetricEigen DecomposeSymmetric(const Eigen::MatrixXd& a,
                                  EigenvectorsToo vectors = EigenvectorsToo::kYes);

// The singular values (descending) and the full right singular vectors V
// (columns) of A = U S V^T (Eigen::JacobiSVD with ComputeFullV).
struct RightSingularVectors {
  Eigen::VectorXd values;
  Eigen::MatrixXd v;
};
RightSingularVectors DecomposeSingular(const Eigen::MatrixXd& a);

}  // namespace tiltcal::linear_algebra

#endif  // TILTCAL_COMMON_LINEAR_ALGEBRA_DENSE_DECOMPOSITIONS_H_
