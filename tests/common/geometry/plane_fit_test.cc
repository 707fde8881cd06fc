#include "common/geometry/plane_fit.h"

#include <algorithm>
#include <functional>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>
#include "common/geometry/angles.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::geometry {
namespace {

struct Cloud {
  std::vector<float> x, y, z;
  void Add(const Eigen::Vector3d& p) {
    x.push_back(static_cast<float>(p.x()));
    y.push_back(static_cast<float>(p.y()));
    z.push_back(static_cast<float>(p.z()));
  }
  size_t size() const { return x.size(); }
};

// Points on the plane n·p + d = 0 inside a disc of radius `radius` around the
// foot of the origin, with Gaussian noise `sigma` along n.
Cloud PlanePoints(const Eigen::Vector3d& n, double d, int count, double radius, double sigma,
                  std::mt19937* rng) {
  std::uniform_real_distribution<double> u(-radius, radius);
  std::normal_distribution<double> noise(0.0, sigma);
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  Cloud cloud;
  for (int i = 0; i < count; ++i) {
    // Drawn normal offset, then e2, then e1 (tests/testing/random_vector.h).
    const double offset = noise(*rng);
    const double along_e2 = u(*rng);
    const double along_e1 = u(*rng);
    cloud.Add(-d * n + along_e1 * e1 + along_e2 * e2 + offset * n);
  }
  return cloud;
}

PlaneFit FitAll(const Cloud& c) {
  PlaneMoments m(Eigen::Vector3d(c.x[0], c.y[0], c.z[0]));
  for (size_t i = 0; i < c.size(); ++i) m.Add(c.x[i], c.y[i], c.z[i]);
  return FitPlane(m);
}

TEST(PlaneFit, RecoversANoiseFreePlane) {
  std::mt19937 rng(1);
  const Eigen::Vector3d n = Eigen::Vector3d(0.1, -0.2, 1.0).normalized();
  const Cloud c = PlanePoints(n, 1.5, 500, 10.0, 0.0, &rng);
  const PlaneFit fit = FitAll(c);
  ASSERT_TRUE(fit.ok);
  EXPECT_LT((fit.normal - n).norm(), 1e-6);
  EXPECT_NEAR(fit.offset, 1.5, 1e-5);
  EXPECT_LT(fit.eigenvalues(0), 1e-10);
}

TEST(PlaneFit, MomentsMatchDirectCovarianceFarFromTheOrigin) {
  std::mt19937 rng(2);
  const Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  Cloud c = PlanePoints(n, -1000.0, 200, 2.0, 0.01, &rng);  // plane z = 1000 m
  const PlaneFit fit = FitAll(c);
  ASSERT_TRUE(fit.ok);
  // Direct two-pass covariance as the oracle.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < c.size(); ++i) mean += Eigen::Vector3d(c.x[i], c.y[i], c.z[i]);
  mean /= static_cast<double>(c.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < c.size(); ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(c.x[i], c.y[i], c.z[i]) - mean;
    cov += d * d.transpose();
  }
  cov /= static_cast<double>(c.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  EXPECT_NEAR(fit.eigenvalues(0), solver.eigenvalues()(0), 1e-9);
  EXPECT_NEAR(std::fabs(fit.normal.dot(solver.eigenvectors().col(0))), 1.0, 1e-9);
  EXPECT_LT((fit.centroid - mean).norm(), 1e-9);
}

TEST(PlaneFit, DegenerateInputsFailWithoutNan) {
  PlaneMoments empty;
  EXPECT_FALSE(FitPlane(empty).ok);
  PlaneMoments two;
  two.Add(0, 0, 0);
  two.Add(1, 0, 0);
  EXPECT_FALSE(FitPlane(two).ok);
  PlaneMoments line;
  for (int i = 0; i < 100; ++i) line.Add(0.1 * i, 0.2 * i, -1.0);
  EXPECT_FALSE(FitPlane(line).ok);
  PlaneMoments spot;
  for (int i = 0; i < 100; ++i) spot.Add(1.0, 2.0, 3.0);
  EXPECT_FALSE(FitPlane(spot).ok);
  PlaneMoments nan;
  nan.Add(0, 0, 0);
  nan.Add(1, 0, 0);
  nan.Add(0, 1, std::numeric_limits<double>::quiet_NaN());
  const PlaneFit fit = FitPlane(nan);
  EXPECT_FALSE(fit.ok);
  EXPECT_TRUE(PlaneCovariance(fit, 1.0).isZero());
}

TEST(PlaneFit, OrientTowardsPutsTheViewpointOnThePositiveSide) {
  std::mt19937 rng(3);
  const Cloud c = PlanePoints(Eigen::Vector3d::UnitZ(), 1.7, 100, 5.0, 0.0, &rng);
  PlaneFit fit = FitAll(c);  // plane z = -1.7
  ASSERT_TRUE(fit.ok);
  OrientTowards(Eigen::Vector3d(0, 0, -10), &fit);  // viewpoint below the plane
  EXPECT_NEAR(fit.normal.z(), -1.0, 1e-9);
  EXPECT_NEAR(fit.offset, -1.7, 1e-5);
  OrientTowards(Eigen::Vector3d::Zero(), &fit);
  EXPECT_NEAR(fit.normal.z(), 1.0, 1e-9);
  EXPECT_NEAR(fit.offset, 1.7, 1e-5);
  EXPECT_LT((fit.eigenvectors.col(0) - fit.normal).norm(), 1e-12);
}

TEST(PlaneFit, CovarianceMatchesMonteCarlo) {
  // Predicted covariance of (n, d) against the spread over many noisy fits.
  const Eigen::Vector3d n = Eigen::Vector3d(0.05, 0.1, 1.0).normalized();
  const double d = 1.2, sigma = 0.02;
  std::mt19937 rng(4);
  const int trials = 400;
  std::vector<Eigen::Vector4d> samples;
  Eigen::Matrix4d predicted = Eigen::Matrix4d::Zero();
  // A disc that does not contain the foot of the origin, so n and d correlate.
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::normal_distribution<double> noise(0.0, sigma);
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  for (int t = 0; t < trials; ++t) {
    Cloud c;
    for (int i = 0; i < 300; ++i) {
      // Drawn normal offset, then e2, then e1 (tests/testing/random_vector.h).
      const double offset = noise(rng);
      const double along_e2 = u(rng);
      const double along_e1 = u(rng);
      c.Add(-d * n + (5.0 + along_e1) * e1 + along_e2 * e2 + offset * n);
    }
    PlaneFit fit = FitAll(c);
    ASSERT_TRUE(fit.ok);
    OrientTowards(Eigen::Vector3d::Zero(), &fit);
    samples.emplace_back(fit.normal.x(), fit.normal.y(), fit.normal.z(), fit.offset);
    predicted += PlaneCovariance(fit, PlaneNoiseVariance(fit));
  }
  predicted /= trials;
  Eigen::Vector4d mean = Eigen::Vector4d::Zero();
  for (const auto& s : samples) mean += s;
  mean /= trials;
  Eigen::Matrix4d empirical = Eigen::Matrix4d::Zero();
  for (const auto& s : samples) empirical += (s - mean) * (s - mean).transpose();
  empirical /= trials - 1;
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(std::sqrt(empirical(i, i)), std::sqrt(predicted(i, i)),
                0.15 * std::sqrt(predicted(i, i)) + 1e-7)
        << "component " << i;
  }
  // Cross term n_x / d (lever arm along e1) with the right sign and size.
  const int a = std::fabs(e1.x()) > std::fabs(e1.y()) ? 0 : 1;
  const double corr_emp = empirical(a, 3) / std::sqrt(empirical(a, a) * empirical(3, 3));
  const double corr_pred = predicted(a, 3) / std::sqrt(predicted(a, a) * predicted(3, 3));
  EXPECT_NEAR(corr_emp, corr_pred, 0.15);
}

TEST(PlaneFit, RobustFitIgnoresOutliers) {
  std::mt19937 rng(5);
  const Eigen::Vector3d n = Eigen::Vector3d(0.0, 0.1, 1.0).normalized();
  Cloud c = PlanePoints(n, 0.9, 2000, 8.0, 0.01, &rng);
  std::uniform_real_distribution<double> u(-8.0, 8.0);
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d v = tiltcal::testing::RandomVector3(u, rng);
    c.Add(Eigen::Vector3d(v.x(), v.y(), 0.5 + 0.1 * v.z()));
  }
  RobustPlaneOptions options;
  options.inlier_distance_m = 0.05;
  options.max_iterations = 10;
  std::vector<uint8_t> inlier;
  const PlaneFit plain = FitAll(c);
  const PlaneFit robust =
      FitPlaneRobust(c.x.data(), c.y.data(), c.z.data(), c.size(), options, &inlier);
  ASSERT_TRUE(robust.ok);
  const double robust_err = RadToDeg(std::acos(std::min(1.0, robust.normal.dot(n))));
  const double plain_err = RadToDeg(std::acos(std::min(1.0, plain.normal.dot(n))));
  EXPECT_LT(robust_err, 0.1);
  EXPECT_GT(plain_err, robust_err);
  EXPECT_NEAR(robust.offset, 0.9, 0.005);
  int kept_outliers = 0;
  for (size_t i = 2000; i < c.size(); ++i) kept_outliers += inlier[i];
  EXPECT_LT(kept_outliers, 20);
  EXPECT_EQ(robust.num_points,
            static_cast<int64_t>(std::count(inlier.begin(), inlier.end(), uint8_t{1})));
}

TEST(PlaneFit, RefinementFromAHypothesisStaysOnItsSurface) {
  // A road and a sidewalk 15 cm higher beside it: plain trimming from the
  // least-squares plane may settle between them; starting from a road
  // hypothesis with a fixed band keeps the road.
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> ux(-8.0, 8.0), uy_road(-6.0, 2.5), uy_walk(2.5, 6.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  Cloud c;
  // Each point drawn z, y, x (tests/testing/random_vector.h).
  auto add = [&](std::uniform_real_distribution<double>& uy, double height, int count) {
    for (int i = 0; i < count; ++i) {
      const double z = height + noise(rng);
      const double y = uy(rng);
      const double x = ux(rng);
      c.Add(Eigen::Vector3d(x, y, z));
    }
  };
  add(uy_road, -0.9, 3000);
  add(uy_walk, -0.75, 1500);
  RobustPlaneOptions options;
  options.inlier_distance_m = 0.08;
  options.max_iterations = 10;
  std::vector<uint8_t> inlier;
  const Eigen::Vector3d hypothesis = Eigen::Vector3d(0.0, 0.01, 1.0).normalized();
  const PlaneFit fit = FitPlaneRobustFrom(c.x.data(), c.y.data(), c.z.data(), c.size(),
                                          hypothesis, 0.9, options, &inlier);
  ASSERT_TRUE(fit.ok);
  EXPECT_LT(RadToDeg(std::acos(std::min(1.0, fit.normal.z()))), 0.05);
  EXPECT_NEAR(fit.offset, 0.9, 0.002);
  EXPECT_EQ(fit.num_points, 3000);
  // Scoring: the road hypothesis has more support than the sidewalk one.
  const size_t road = CountWithinBand(c.x.data(), c.y.data(), c.z.data(), c.size(), 1,
                                      Eigen::Vector3d::UnitZ(), 0.9, 0.05);
  const size_t walk = CountWithinBand(c.x.data(), c.y.data(), c.z.data(), c.size(), 1,
                                      Eigen::Vector3d::UnitZ(), 0.75, 0.05);
  EXPECT_EQ(road, 3000u);
  EXPECT_EQ(walk, 1500u);
  EXPECT_EQ(CountWithinBand(c.x.data(), c.y.data(), c.z.data(), c.size(), 3,
                            Eigen::Vector3d::UnitZ(), 0.9, 0.05),
            1000u);
}

TEST(PlaneFit, SelectAndAccumulateMatchesAPlainLoop) {
  std::mt19937 rng(6);
  const Eigen::Vector3d n = Eigen::Vector3d(0.02, -0.05, 1.0).normalized();
  const Cloud c = PlanePoints(n, 1.3, 1000, 30.0, 0.05, &rng);
  std::vector<uint8_t> active(c.size()), selected(c.size(), 0);
  for (size_t i = 0; i < c.size(); ++i) active[i] = i % 7 != 0;
  PlaneMoments fast(Eigen::Vector3d(1.0, 2.0, -1.0)), slow(Eigen::Vector3d(1.0, 2.0, -1.0));
  EXPECT_TRUE(SelectAndAccumulate(c.x.data(), c.y.data(), c.z.data(), c.size(), active.data(), n,
                                  1.3, 0.04, selected.data(), &fast));
  for (size_t i = 0; i < c.size(); ++i) {
    const Eigen::Vector3d p(c.x[i], c.y[i], c.z[i]);
    const bool in = active[i] && std::fabs(n.dot(p) + 1.3) < 0.04;
    EXPECT_EQ(selected[i], in ? 1 : 0) << i;
    if (in) slow.Add(p.x(), p.y(), p.z());
  }
  EXPECT_EQ(fast.count(), slow.count());
  EXPECT_LT((fast.Mean() - slow.Mean()).norm(), 1e-5);
  EXPECT_LT((fast.Covariance() - slow.Covariance()).norm(), 1e-4);
  // Same selection again: nothing changed.
  PlaneMoments again(Eigen::Vector3d::Zero());
  EXPECT_FALSE(SelectAndAccumulate(c.x.data(), c.y.data(), c.z.data(), c.size(), active.data(),
                                   n, 1.3, 0.04, selected.data(), &again));
}

TEST(PlaneFit, MeanOfLowestMatchesSorting) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-3.0f, 1.0f);
  std::vector<float> v(500);
  for (float& value : v) value = u(rng);
  std::vector<float> kept;
  for (float value : v) {
    if (value >= -2.5f) kept.push_back(value);
  }
  std::sort(kept.begin(), kept.end());
  double expected = 0.0;
  for (int i = 0; i < 20; ++i) expected += kept[i];
  EXPECT_NEAR(MeanOfLowest(v.data(), v.size(), nullptr, 20, -2.5f), expected / 20.0, 1e-5);
  EXPECT_TRUE(std::isnan(MeanOfLowest(v.data(), v.size(), nullptr, 20, 5.0f)));
  EXPECT_NEAR(MeanOfLowest(v.data(), 3, nullptr, 20, -10.0f), (v[0] + v[1] + v[2]) / 3.0, 1e-6);
  // Values in decreasing and increasing order, with an activity mask.
  std::vector<float> sorted_desc = v;
  std::sort(sorted_desc.begin(), sorted_desc.end(), std::greater<float>());
  std::vector<uint8_t> active(v.size(), 1);
  active[v.size() - 1] = 0;  // the smallest value is inactive
  std::vector<float> expected_values(sorted_desc.begin(), sorted_desc.end() - 1);
  std::sort(expected_values.begin(), expected_values.end());
  double expected_active = 0.0;
  for (int i = 0; i < 20; ++i) expected_active += expected_values[i];
  EXPECT_NEAR(MeanOfLowest(sorted_desc.data(), sorted_desc.size(), active.data(), 20, -10.0f),
              expected_active / 20.0, 1e-5);
  std::vector<float> sorted_asc(sorted_desc.rbegin(), sorted_desc.rend());
  double expected_all = 0.0;
  for (int i = 0; i < 20; ++i) expected_all += sorted_asc[i];
  EXPECT_NEAR(MeanOfLowest(sorted_asc.data(), sorted_asc.size(), nullptr, 20, -10.0f),
              expected_all / 20.0, 1e-5);
}

}  // namespace
}  // namespace tiltcal::geometry
