// The entries of H^{-1} on H's pattern (Takahashi's recursion) against the
// dense inverse, and its rank test.

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "stages/calibrate/report/selected_inverse.h"
#include "tests/stages/calibrate/report/banded_jacobian.h"

namespace tiltcal::calibrate {
namespace {

// J^T J of a spline-like Jacobian, units over 6 orders of magnitude.
Eigen::MatrixXd BandedNormalMatrix(int rows, int n, int k, unsigned seed) {
  const Eigen::MatrixXd j = testing::BandedJacobian(rows, n, k, seed, 7);
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
