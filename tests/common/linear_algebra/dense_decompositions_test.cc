#include "common/linear_algebra/dense_decompositions.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include <Eigen/Core>

namespace tiltcal::linear_algebra {
namespace {

// A symmetric positive definite n x n matrix with condition number ~10.
Eigen::MatrixXd PositiveDefinite(int n) {
  const Eigen::MatrixXd m = Eigen::MatrixXd::Random(n, n);
  return m * m.transpose() + n * Eigen::MatrixXd::Identity(n, n);
}

TEST(DenseDecompositions, InverseAndLuSolveAgainstTheProductWithA) {
  std::srand(1);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(7, 7) + 4.0 * Eigen::MatrixXd::Identity(7, 7);
  EXPECT_LT((a * Inverse(a) - Eigen::MatrixXd::Identity(7, 7)).norm(), 1e-12);
  const Eigen::MatrixXd b = Eigen::MatrixXd::Random(7, 3);
  EXPECT_LT((a * SolveByLu(a, b) - b).norm(), 1e-12);
}

TEST(DenseDecompositions, LdltSolvesAPositiveDefiniteSystemAndReportsAFailure) {
  std::srand(2);
  const Eigen::MatrixXd a = PositiveDefinite(6);
  const Eigen::VectorXd b = Eigen::VectorXd::Random(6);
  bool factorised = false;
  const Eigen::VectorXd x = SolveByLdlt(a, b, &factorised);
  EXPECT_TRUE(factorised);
  EXPECT_LT((a * x - b).norm(), 1e-12);
  // Zero diagonal, non-zero off-diagonal: no LDLT with symmetric pivoting.
  Eigen::MatrixXd indefinite(2, 2);
  indefinite << 0.0, 1.0, 1.0, 0.0;
  SolveByLdlt(indefinite, Eigen::VectorXd::Ones(2), &factorised);
  EXPECT_FALSE(factorised);
}

TEST(DenseDecompositions, SymmetricEigenRebuildsTheMatrixFromItsLowerTriangle) {
  std::srand(3);
  const Eigen::MatrixXd a = PositiveDefinite(7);
  Eigen::MatrixXd lower_only = a.triangularView<Eigen::Lower>();
  const SymmetricEigen eig = DecomposeSymmetric(lower_only);
  ASSERT_TRUE(eig.converged);
  ASSERT_EQ(eig.vectors.cols(), 7);
  EXPECT_LT((eig.vectors * eig.values.asDiagonal() * eig.vectors.transpose() - a).norm(),
            1e-12 * a.norm());
  EXPECT_LT((eig.vectors.transpose() * eig.vectors - Eigen::MatrixXd::Identity(7, 7)).norm(), 1e-12);
  for (int k = 1; k < 7; ++k) EXPECT_LE(eig.values[k - 1], eig.values[k]);

  const SymmetricEigen values_only = DecomposeSymmetric(a, EigenvectorsToo::kNo);
  EXPECT_TRUE(values_only.converged);
  EXPECT_EQ(values_only.vectors.size(), 0);
  EXPECT_LT((values_only.values - eig.values).norm(), 1e-12 * a.norm());
}

TEST(DenseDecompositions, SingularValuesAreTheLengthsOfAV) {
  std::srand(4);
  const Eigen::MatrixXd a = Eigen::MatrixXd::Random(12, 4);
  const RightSingularVectors svd = DecomposeSingular(a);
  ASSERT_EQ(svd.values.size(), 4);
  ASSERT_EQ(svd.v.rows(), 4);
  ASSERT_EQ(svd.v.cols(), 4);
  EXPECT_LT((svd.v.transpose() * svd.v - Eigen::MatrixXd::Identity(4, 4)).norm(), 1e-12);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR((a * svd.v.col(k)).norm(), svd.values[k], 1e-12);
    if (k > 0) {
      EXPECT_LE(svd.values[k], svd.values[k - 1]);
    }
  }
  // A V = U S with orthogonal U: the columns of A V are orthogonal.
  const Eigen::MatrixXd av = a * svd.v;
  const Eigen::MatrixXd gram = av.transpose() * av;
  EXPECT_LT((gram - Eigen::MatrixXd(gram.diagonal().asDiagonal())).norm(), 1e-12);
}

}  // namespace
}  // namespace tiltcal::linear_algebra
