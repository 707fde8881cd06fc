// The entries of H^{-1} on H's pattern (Takahashi's recursion) against the
// dense inverse, and its rank test.

#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "stages/calibrate/report/selected_inverse.h"

namespace tiltcal::calibrate {
namespace {

// J^T J of a spline-like Jacobian: each row touches 4 consecutive columns of
// the first n - k and every one of the last k; column j scaled by
// 10^(j mod 7 - 3).
Eigen::MatrixXd BandedNormalMatrix(int rows, int n, int k, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd j = Eigen::MatrixXd::Zero(rows, n);
  const int band = n - k;
  for (int r = 0; r < rows; ++r) {
    const int first = (r * (band - 3)) / rows;
    for (int c = first; c < first + 4; ++c) j(r, c) = normal(rng);
    for (int c = band; c < n; ++c) j(r, c) = normal(rng);
  }
  for (int c = 0; c < n; ++c) j.col(c) *= std::pow(10.0, c % 7 - 3);
  return j.transpose() * j;
}

TEST(SelectedInverseTest, EqualsTheDenseInverseOnThePattern) {
  for (const unsigned seed : {1u, 2u, 3u}) {
    const Eigen::MatrixXd h = BandedNormalMatrix(500, 90, 5, seed);
    const Eigen::MatrixXd expected = h.inverse();
    const Eigen::SparseMatrix<double> sparse = h.sparseView(0.0, 0.0);
    Eigen::SparseMatrix<double> inverse;
    const Status status = InverseOnPattern(sparse, 1e-14, &inverse);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(inverse.nonZeros(), sparse.nonZeros());
    for (int c = 0; c < inverse.outerSize(); ++c) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(inverse, c); it; ++it) {
        const auto r = static_cast<int>(it.row());
        EXPECT_NEAR(it.value(), expected(r, c), 1e-8 * std::sqrt(expected(r, r) * expected(c, c)))
            << seed << " " << r << " " << c;
      }
    }
    // tr(H^{-1} H) = n from the pattern alone.
    EXPECT_NEAR(inverse.cwiseProduct(sparse).sum(), 90.0, 1e-8);
  }
}

TEST(SelectedInverseTest, RankDeficiencyIsAnError) {
  const Eigen::MatrixXd h = BandedNormalMatrix(200, 30, 2, 4);
  Eigen::SparseMatrix<double> inverse;
  // Parameter 7 without information.
  Eigen::MatrixXd j = Eigen::MatrixXd::Identity(30, 30);
  j(7, 7) = 0.0;
  Status status = InverseOnPattern((j.transpose() * h * j).sparseView(0.0, 0.0), 1e-14, &inverse);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("parameter 7 of 30 has no information"), std::string::npos)
      << status.message();
  // Parameter 7 twice parameter 6, up to 1e-9 of its own: the unit-diagonal
  // matrix has a pivot of about 1e-18.
  j(6, 7) = 2.0;
  j(7, 7) = 1e-9;
  status = InverseOnPattern((j.transpose() * h * j).sparseView(0.0, 0.0), 1e-14, &inverse);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("rank deficient"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace tiltcal::calibrate
