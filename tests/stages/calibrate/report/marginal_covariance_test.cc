// The marginal covariance of the last columns (Schur complement of J^T J)
// against the dense inverse, and its rank tests.

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "stages/calibrate/report/marginal_covariance.h"
#include "tests/stages/calibrate/report/banded_jacobian.h"

namespace tiltcal::calibrate {
namespace {

using RowMajorSparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// A spline-like Jacobian whose units differ by 8 orders of magnitude.
Eigen::MatrixXd BandedJacobian(int rows, int n, int k, unsigned seed) {
  return testing::BandedJacobian(rows, n, k, seed, 9);
}

TEST(MarginalCovarianceTest, EqualsTheBlockOfTheDenseInverse) {
  for (const unsigned seed : {1u, 2u, 3u}) {
    const int k = 7;
    const Eigen::MatrixXd j = BandedJacobian(600, 127, k, seed);
    const Eigen::MatrixXd expected =
        (j.transpose() * j).inverse().bottomRightCorner(k, k);
    Eigen::MatrixXd covariance;
    const Status status = MarginalCovarianceOfLastColumns(j.sparseView(), k, 1e-14, &covariance);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_EQ(covariance.rows(), k);
    ASSERT_EQ(covariance.cols(), k);
    for (int r = 0; r < k; ++r) {
      for (int c = 0; c < k; ++c) {
        EXPECT_NEAR(covariance(r, c), expected(r, c),
                    1e-8 * std::sqrt(expected(r, r) * expected(c, c)))
            << seed << " " << r << " " << c;
      }
    }
  }
}

TEST(MarginalCovarianceTest, AllColumnsAndOneColumn) {
  const Eigen::MatrixXd j = BandedJacobian(50, 9, 2, 4);
  Eigen::MatrixXd all;
  ASSERT_TRUE(MarginalCovarianceOfLastColumns(j.sparseView(), 9, 1e-14, &all).ok());
  EXPECT_LT((all - (j.transpose() * j).inverse()).norm(), 1e-9 * all.norm());
  Eigen::MatrixXd one;
  ASSERT_TRUE(MarginalCovarianceOfLastColumns(j.sparseView(), 1, 1e-14, &one).ok());
  EXPECT_NEAR(one(0, 0), (j.transpose() * j).inverse()(8, 8), 1e-9 * one(0, 0));
}

TEST(MarginalCovarianceTest, RankDeficiencyIsAnError) {
  const int k = 3;
  const Eigen::MatrixXd full = BandedJacobian(200, 40, k, 5);
  Eigen::MatrixXd covariance;

  // A column without residuals.
  Eigen::MatrixXd zero_column = full;
  zero_column.col(10).setZero();
  Status status = MarginalCovarianceOfLastColumns(zero_column.sparseView(), k, 1e-14, &covariance);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("parameter 10 of 40 has no residual"), std::string::npos)
      << status.message();

  // Two knot columns that only appear together (a combination the data
  // cannot separate).
  Eigen::MatrixXd twin_knots = full;
  twin_knots.col(11) = 3.0 * twin_knots.col(12);
  status = MarginalCovarianceOfLastColumns(twin_knots.sparseView(), k, 1e-14, &covariance);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("rank deficient"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("not determined by the data"), std::string::npos);

  // A parameter of interest that is a combination of the knots.
  Eigen::MatrixXd twin_extrinsic = full;
  twin_extrinsic.col(39) = twin_extrinsic.col(5) - 2.0 * twin_extrinsic.col(6);
  status = MarginalCovarianceOfLastColumns(twin_extrinsic.sparseView(), k, 1e-14, &covariance);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("the extrinsic and time offset"), std::string::npos)
      << status.message();

  // Nearly dependent (the part of the column outside the others' span is
  // ~1e-3 of its norm): still a covariance, that of a QR of the unit-norm columns
  // (which does not square the condition number).
  Eigen::MatrixXd nearly = full;
  const Eigen::VectorXd combination = nearly.col(5) - 2.0 * nearly.col(6);
  nearly.col(39) = combination + 1e-3 * combination.norm() * nearly.col(39).normalized();
  ASSERT_TRUE(MarginalCovarianceOfLastColumns(nearly.sparseView(), k, 1e-14, &covariance).ok());
  const Eigen::VectorXd column_scale = nearly.colwise().norm().cwiseInverse();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(nearly * column_scale.asDiagonal());
  const Eigen::MatrixXd r_inverse =
      qr.matrixQR().topRows(nearly.cols()).triangularView<Eigen::Upper>().solve(
          Eigen::MatrixXd::Identity(nearly.cols(), nearly.cols()));
  const Eigen::MatrixXd expected = column_scale.asDiagonal() * r_inverse *
                                   r_inverse.transpose() * column_scale.asDiagonal();
  EXPECT_NEAR(covariance(2, 2), expected(39, 39), 1e-6 * expected(39, 39));
}

}  // namespace
}  // namespace tiltcal::calibrate
