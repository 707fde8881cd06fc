// Variance components on a linear least-squares problem with two groups of
// observations of known, different noise: the estimator recovers them, the
// redundancies are the dense algebra's and sum to m - n.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include "stages/calibrate/report/variance_components.h"

namespace tiltcal::calibrate {
namespace {

// y = A x + noise on a banded A (each row touches 3 consecutive of n
// parameters); rows of group 0 have noise sigma_0, group 1 sigma_1 (the
// model says 1 for both). The least-squares residuals at the model's
// weights (e = y - A x_hat) and each group's e^T e.
struct TwoGroupProblem {
  Eigen::MatrixXd a;
  std::vector<int> row_group;
  std::vector<VarianceComponentGroup> groups{2};
};

TwoGroupProblem MakeProblem(int rows_per_group, int n, double sigma_0, double sigma_1,
                            unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  TwoGroupProblem p;
  const int m = 2 * rows_per_group;
  p.a = Eigen::MatrixXd::Zero(m, n);
  Eigen::VectorXd y(m);
  for (int r = 0; r < m; ++r) {
    const int group = r % 2;
    p.row_group.push_back(group);
    const int first = ((r / 2) * (n - 2)) / rows_per_group;
    for (int c = first; c < first + 3; ++c) p.a(r, c) = normal(rng);
    y[r] = (group == 0 ? sigma_0 : sigma_1) * normal(rng);  // x_true = 0
  }
  const Eigen::VectorXd x = p.a.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd e = y - p.a * x;
  for (int r = 0; r < m; ++r) p.groups[static_cast<size_t>(r % 2)].square_sum += e[r] * e[r];
  return p;
}

TEST(VarianceComponentsTest, RecoversTwoGroupsOfDifferentNoise) {
  const double sigma_0 = 0.5;
  const double sigma_1 = 2.0;
  for (const unsigned seed : {1u, 2u}) {
    const TwoGroupProblem p = MakeProblem(4000, 40, sigma_0, sigma_1, seed);
    {
      std::vector<VarianceComponent> c;
      const Status status =
          EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), p.row_group, p.groups, 1e-14, &c);
      ASSERT_TRUE(status.ok()) << status.message();
      ASSERT_EQ(c.size(), 2u);
      // 4000 rows each: the components' relative sigma is about 2 %; the
      // residuals are those of the model's weights, so the noisier group
      // leaks into the other's through the 40 parameters (about 1 %).
      EXPECT_NEAR(c[0].sigma0_squared, sigma_0 * sigma_0, 0.1 * sigma_0 * sigma_0) << seed;
      EXPECT_NEAR(c[1].sigma0_squared, sigma_1 * sigma_1, 0.1 * sigma_1 * sigma_1) << seed;
      EXPECT_DOUBLE_EQ(c[0].weight, 1.0 / c[0].sigma0_squared);
      EXPECT_DOUBLE_EQ(c[1].weight, 1.0 / c[1].sigma0_squared);
      EXPECT_EQ(c[0].rows, 4000);
      EXPECT_NEAR(c[0].redundancy + c[1].redundancy, 8000.0 - 40.0, 1e-6);
    }
    // One factor over both (2F / (m - n)) is between them and fits neither.
    const double one = (p.groups[0].square_sum + p.groups[1].square_sum) / (8000.0 - 40.0);
    EXPECT_GT(one, 4.0 * sigma_0 * sigma_0);
    EXPECT_LT(one, 0.75 * sigma_1 * sigma_1);
  }
}

// r_k = n_k - tr(J_k H^{-1} J_k^T) against dense algebra.
TEST(VarianceComponentsTest, RedundanciesEqualTheDenseOnes) {
  const TwoGroupProblem p = MakeProblem(150, 40, 0.3, 1.5, 3);
  Eigen::MatrixXd j0 = p.a;
  Eigen::MatrixXd j1 = p.a;
  for (int r = 0; r < p.a.rows(); ++r) {
    (p.row_group[static_cast<size_t>(r)] == 0 ? j1 : j0).row(r).setZero();
  }
  const Eigen::MatrixXd h_inverse = (p.a.transpose() * p.a).inverse();
  std::vector<VarianceComponent> c;
  ASSERT_TRUE(
      EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), p.row_group, p.groups, 1e-14, &c).ok());
  EXPECT_NEAR(c[0].redundancy, 150.0 - (j0 * h_inverse * j0.transpose()).trace(), 1e-8);
  EXPECT_NEAR(c[1].redundancy, 150.0 - (j1 * h_inverse * j1.transpose()).trace(), 1e-8);
  EXPECT_NEAR(c[0].redundancy + c[1].redundancy, 300.0 - 40.0, 1e-8);
  EXPECT_NEAR(c[0].sigma0_squared, p.groups[0].square_sum / c[0].redundancy, 1e-12);
  EXPECT_NEAR(c[1].sigma0_squared, p.groups[1].square_sum / c[1].redundancy, 1e-12);
}

// A group held (not estimated) keeps weight 1; one with a floor of 1 keeps
// its estimate but a weight of at most 1.
TEST(VarianceComponentsTest, HeldAndNonShrinkingGroups) {
  TwoGroupProblem p = MakeProblem(1000, 100, 0.5, 2.0, 4);
  p.groups[0].floor = 1.0;
  p.groups[1].estimated = false;
  std::vector<VarianceComponent> c;
  ASSERT_TRUE(
      EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), p.row_group, p.groups, 1e-14, &c).ok());
  EXPECT_LT(c[0].sigma0_squared, 0.5);
  EXPECT_DOUBLE_EQ(c[0].weight, 1.0);
  EXPECT_DOUBLE_EQ(c[1].sigma0_squared, 1.0);
  EXPECT_DOUBLE_EQ(c[1].weight, 1.0);
  // A row outside the groups is an error.
  std::vector<int> bad = p.row_group;
  bad[5] = 2;
  EXPECT_FALSE(
      EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), bad, p.groups, 1e-14, &c).ok());
}

// A group whose errors stay correlated has its information divided by tau
// as well; tau below 1 is not credited, and a floor bounds s tau from below.
TEST(VarianceComponentsTest, CorrelatedErrorsDivideTheWeight) {
  TwoGroupProblem p = MakeProblem(1000, 100, 0.5, 2.0, 4);
  p.groups[0].correlation = 6.0;
  p.groups[1].correlation = 0.3;
  std::vector<VarianceComponent> c;
  ASSERT_TRUE(
      EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), p.row_group, p.groups, 1e-14, &c).ok());
  EXPECT_DOUBLE_EQ(c[0].correlation, 6.0);
  EXPECT_DOUBLE_EQ(c[0].weight, 1.0 / (6.0 * c[0].sigma0_squared));
  EXPECT_DOUBLE_EQ(c[1].correlation, 1.0);
  EXPECT_DOUBLE_EQ(c[1].weight, 1.0 / c[1].sigma0_squared);
  // s_0 ~ 0.25: s tau ~ 1.5 above a floor of 1 divides the group; tau 2
  // (s tau ~ 0.5) leaves it at the floor, as does a floor of 0.8.
  p.groups[0].floor = 1.0;
  ASSERT_TRUE(
      EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), p.row_group, p.groups, 1e-14, &c).ok());
  ASSERT_GT(6.0 * c[0].sigma0_squared, 1.0);
  EXPECT_DOUBLE_EQ(c[0].weight, 1.0 / (6.0 * c[0].sigma0_squared));
  p.groups[0].correlation = 2.0;
  ASSERT_TRUE(
      EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), p.row_group, p.groups, 1e-14, &c).ok());
  ASSERT_LT(2.0 * c[0].sigma0_squared, 1.0);
  EXPECT_DOUBLE_EQ(c[0].weight, 1.0);
  p.groups[0].floor = 0.8;
  ASSERT_TRUE(
      EstimateVarianceComponents(p.a.sparseView(0.0, 0.0), p.row_group, p.groups, 1e-14, &c).ok());
  EXPECT_DOUBLE_EQ(c[0].weight, 1.0 / 0.8);
}

}  // namespace
}  // namespace tiltcal::calibrate
