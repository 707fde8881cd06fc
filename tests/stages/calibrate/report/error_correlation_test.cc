// The batch-means estimate of how long errors stay correlated: about 1 for
// independent errors, (1 + rho) / (1 - rho) for an AR(1) series, pooled over
// the components of a group's blocks and blind to the other groups' rows.

#include "stages/calibrate/report/error_correlation.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>
#include <random>
#include <vector>

namespace tiltcal::calibrate {
namespace {

// e_n = rho e_{n-1} + sqrt(1 - rho^2) w_n: unit variance, autocorrelation
// rho^j.
std::vector<double> Ar1(int n, double rho, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  std::vector<double> e(static_cast<size_t>(n));
  double previous = normal(*rng);
  for (double& v : e) {
    v = rho * previous + std::sqrt(1.0 - rho * rho) * normal(*rng);
    previous = v;
  }
  return e;
}

double Ratio(const BatchMeansVariances& v) { return v.batch_means / v.values; }

TEST(ErrorCorrelationTest, IndependentErrorsGiveAboutOne) {
  // 20 batches: relative standard error sqrt(2 / 19) = 0.32 per series;
  // averaged over 40 series 0.05.
  std::mt19937 rng(7);
  double sum = 0.0;
  for (int i = 0; i < 40; ++i) sum += Ratio(BatchMeans(Ar1(400, 0.0, &rng), 20));
  EXPECT_NEAR(sum / 40.0, 1.0, 0.2);
}

TEST(ErrorCorrelationTest, Ar1ErrorsGiveTheVarianceOfTheirMean) {
  // rho 0.8: tau = 9, a correlation time of about 5 values against batches
  // of 100.
  std::mt19937 rng(11);
  double sum = 0.0;
  for (int i = 0; i < 40; ++i) sum += Ratio(BatchMeans(Ar1(2000, 0.8, &rng), 20));
  EXPECT_NEAR(sum / 40.0, 9.0, 9.0 * 0.15);
  // Oscillating errors (rho < 0) cancel in a mean: tau below 1.
  double oscillating = 0.0;
  for (int i = 0; i < 40; ++i) oscillating += Ratio(BatchMeans(Ar1(2000, -0.8, &rng), 20));
  EXPECT_LT(oscillating / 40.0, 0.3);
}

TEST(ErrorCorrelationTest, TooShortOrConstantSeriesHaveNoEstimate) {
  const BatchMeansVariances short_series = BatchMeans(std::vector<double>(39, 1.0), 20);
  EXPECT_EQ(short_series.batch_means, 0.0);
  EXPECT_EQ(short_series.values, 0.0);
  EXPECT_EQ(BatchMeans(std::vector<double>(100, 1.0), 1).values, 0.0);
  const Eigen::VectorXd constant = Eigen::VectorXd::Constant(100, 0.5);
  EXPECT_EQ(PooledBatchMeansCorrelation(constant, std::vector<int>(100, 0),
                                        std::vector<int>(100, 0), 0, 20),
            1.0);
}

TEST(ErrorCorrelationTest, PoolsTheComponentsOfOneGroupOnly) {
  // Group 3: blocks of 3 rows whose components are AR(1) series (rho 0.8),
  // interleaved with group 1's white rows. Pooled, tau ~ 9; group 1 ~ 1.
  std::mt19937 rng(5);
  const int blocks = 2000;
  std::vector<std::vector<double>> components;
  for (int c = 0; c < 3; ++c) components.push_back(Ar1(blocks, 0.8, &rng));
  std::normal_distribution<double> normal;
  std::vector<double> residuals;
  std::vector<int> row_group;
  std::vector<int> row_component;
  for (int b = 0; b < blocks; ++b) {
    for (int c = 0; c < 3; ++c) {
      residuals.push_back(components[static_cast<size_t>(c)][static_cast<size_t>(b)]);
      row_group.push_back(3);
      row_component.push_back(c);
    }
    residuals.push_back(normal(rng));
    row_group.push_back(1);
    row_component.push_back(0);
  }
  const Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(
      residuals.data(), static_cast<Eigen::Index>(residuals.size()));
  const double pooled = PooledBatchMeansCorrelation(r, row_group, row_component, 3, 20);
  double separate = 0.0;
  for (int c = 0; c < 3; ++c)
    separate += BatchMeans(components[static_cast<size_t>(c)], 20).batch_means;
  double variances = 0.0;
  for (int c = 0; c < 3; ++c)
    variances += BatchMeans(components[static_cast<size_t>(c)], 20).values;
  EXPECT_DOUBLE_EQ(pooled, separate / variances);
  EXPECT_NEAR(pooled, 9.0, 9.0 * 0.3);
  EXPECT_NEAR(PooledBatchMeansCorrelation(r, row_group, row_component, 1, 20), 1.0, 0.6);
  // A group with no rows: 1.
  EXPECT_EQ(PooledBatchMeansCorrelation(r, row_group, row_component, 4, 20), 1.0);
}

}  // namespace
}  // namespace tiltcal::calibrate
