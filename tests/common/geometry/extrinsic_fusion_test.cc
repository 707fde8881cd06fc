#include "common/geometry/extrinsic_fusion.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include "common/geometry/so3.h"

namespace tiltcal::geometry {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// A random covariance with sigmas ~ 0.1 deg (rotation), ~ 3 mm (translation)
// and correlations.
MatrixXd RandomCovariance(std::mt19937* rng, int n) {
  std::normal_distribution<double> normal;
  MatrixXd a(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) a(i, j) = normal(*rng);
  }
  VectorXd scale(n);
  for (int i = 0; i < n; ++i) scale[i] = i < 3 ? 0.002 : (i < 6 ? 0.003 : 1e-4);
  const MatrixXd c = a * a.transpose() / n + 0.2 * MatrixXd::Identity(n, n);
  return scale.asDiagonal() * c * scale.asDiagonal();
}

VectorXd Draw(std::mt19937* rng, const MatrixXd& covariance) {
  std::normal_distribution<double> normal;
  VectorXd z(covariance.rows());
  for (int i = 0; i < z.size(); ++i) z[i] = normal(*rng);
  return covariance.llt().matrixL() * z;
}

struct Truth {
  Eigen::Quaterniond rotation{Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized())};
  VectorXd rest;
};

// An estimate whose error against the truth is drawn from its covariance:
// truth = estimate (+) error.
ExtrinsicEstimate NoisyEstimate(std::mt19937* rng, const Truth& truth, const MatrixXd& covariance) {
  const VectorXd e = Draw(rng, covariance);
  ExtrinsicEstimate estimate;
  estimate.rotation = BoxPlus(truth.rotation, -e.head<3>());
  estimate.rest = truth.rest - e.tail(e.size() - 3);
  estimate.covariance = covariance;
  return estimate;
}

TEST(ExtrinsicFusion, TwoEstimatesGiveTheInformationWeightedMean) {
  ExtrinsicEstimate a, b;
  a.rotation = Eigen::Quaterniond::Identity();
  b.rotation = BoxPlus(a.rotation, Eigen::Vector3d(0.002, 0.0, 0.0));
  a.rest = VectorXd::Zero(3);
  b.rest = Eigen::Vector3d(0.0, 0.01, 0.0);
  a.covariance = MatrixXd::Identity(6, 6) * 1e-6;
  b.covariance = MatrixXd::Identity(6, 6) * 3e-6;
  const FusedExtrinsic fused = FuseExtrinsics({a, b}, ExtrinsicPrior());
  ASSERT_TRUE(fused.converged);
  // Weights 3/4 and 1/4.
  EXPECT_NEAR(BoxMinus(fused.rotation, a.rotation).x(), 0.0005, 1e-9);
  EXPECT_NEAR(fused.rest[1], 0.0025, 1e-12);
  EXPECT_NEAR(fused.covariance(0, 0), 0.75e-6, 1e-12);
  EXPECT_NEAR(fused.covariance(4, 4), 0.75e-6, 1e-15);
}

// Five sequences, 500 trials: the fused error in units of the fused
// covariance is chi^2 with n degrees of freedom; with tau shared (n = 7) too.
TEST(ExtrinsicFusion, FusedCovarianceIsHonest) {
  for (int n : {6, 7}) {
    std::mt19937 rng(11 + n);
    Truth truth;
    truth.rest = VectorXd::Zero(n - 3);
    truth.rest.head<3>() = Eigen::Vector3d(0.25, -0.07, -0.46);
    std::vector<MatrixXd> covariances;
    for (int i = 0; i < 5; ++i) covariances.push_back(RandomCovariance(&rng, n));
    double nees_sum = 0.0, chi2_sum = 0.0;
    const int trials = 500;
    for (int t = 0; t < trials; ++t) {
      std::vector<ExtrinsicEstimate> estimates;
      for (const MatrixXd& c : covariances) estimates.push_back(NoisyEstimate(&rng, truth, c));
      const FusedExtrinsic fused = FuseExtrinsics(estimates, ExtrinsicPrior());
      ASSERT_TRUE(fused.converged);
      ExtrinsicEstimate at_truth;
      at_truth.rotation = truth.rotation;
      at_truth.rest = truth.rest;
      const VectorXd e = ExtrinsicError(at_truth, fused.rotation, fused.rest);
      nees_sum += e.dot(fused.covariance.ldlt().solve(e));
      const ExtrinsicConsistency c = TestConsistency(estimates[2], fused);
      EXPECT_EQ(c.dof, n);
      chi2_sum += c.chi2;
    }
    // Means of chi^2_n over 500 trials: n +- 3 sqrt(2n / 500).
    EXPECT_NEAR(nees_sum / trials, n, 3.0 * std::sqrt(2.0 * n / trials)) << "n " << n;
    EXPECT_NEAR(chi2_sum / trials, n, 3.0 * std::sqrt(2.0 * n / trials)) << "n " << n;
  }
}

// Each sequence's covariance holds the same prior on the translation along
// z; fused, the prior counts once: H = sum of data information + prior.
TEST(ExtrinsicFusion, ThePriorOfEverySolveCountsOnce) {
  MatrixXd prior = MatrixXd::Zero(6, 6);
  prior(5, 5) = 1.0 / (0.05 * 0.05);
  MatrixXd data = MatrixXd::Identity(6, 6) * 1e6;
  data(5, 5) = 1.0;  // the data hardly see z
  std::vector<ExtrinsicEstimate> estimates(4);
  for (ExtrinsicEstimate& e : estimates) {
    e.rest = VectorXd::Zero(3);
    e.covariance = (data + prior).inverse();
    e.prior_information = prior;
  }
  ExtrinsicPrior once;
  once.rest = VectorXd::Zero(3);
  once.information = prior;
  const FusedExtrinsic fused = FuseExtrinsics(estimates, once);
  EXPECT_NEAR(fused.covariance(5, 5), 1.0 / (4.0 * data(5, 5) + prior(5, 5)), 1e-12);
  // Without the correction the prior would count four times.
  const FusedExtrinsic naive = FuseExtrinsics(
      {estimates[0], estimates[1], estimates[2], estimates[3]}, ExtrinsicPrior());
  EXPECT_NEAR(naive.covariance(5, 5), 1.0 / (4.0 * (data(5, 5) + prior(5, 5))), 1e-12);
}

TEST(ExtrinsicFusion, AnInconsistentSequenceIsNamedByItsComponent) {
  std::mt19937 rng(5);
  Truth truth;
  truth.rest = Eigen::Vector3d(0.25, -0.07, -0.46);
  std::vector<ExtrinsicEstimate> estimates;
  for (int i = 0; i < 5; ++i) {
    estimates.push_back(NoisyEstimate(&rng, truth, RandomCovariance(&rng, 6)));
  }
  // Sequence 3 off by 8 sigma in yaw (rotation about z).
  const double sigma_z = std::sqrt(estimates[3].covariance(2, 2));
  estimates[3].rotation = BoxPlus(estimates[3].rotation, Eigen::Vector3d(0, 0, 8.0 * sigma_z));
  const FusedExtrinsic fused = FuseExtrinsics(estimates, ExtrinsicPrior());
  const ExtrinsicConsistency bad = TestConsistency(estimates[3], fused);
  EXPECT_GT(bad.chi2, ChiSquareUpperQuantile(bad.dof, 0.001));
  EXPECT_EQ(bad.worst_component, 2);
  EXPECT_LT(bad.worst_z, 0.0);  // the joint value lies below this sequence's
}

TEST(ExtrinsicFusion, ChiSquareQuantiles) {
  // Tabulated: chi^2_6 at p = 0.001 is 22.458, chi^2_7 at 0.05 is 14.067.
  EXPECT_NEAR(ChiSquareUpperQuantile(6, 0.001), 22.458, 0.01 * 22.458);
  EXPECT_NEAR(ChiSquareUpperQuantile(7, 0.05), 14.067, 0.01 * 14.067);
}

}  // namespace
}  // namespace tiltcal::geometry
