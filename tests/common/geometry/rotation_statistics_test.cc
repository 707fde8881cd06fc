#include "common/geometry/rotation_statistics.h"

#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/geometry/so3.h"

namespace tiltcal::geometry {
namespace {

Eigen::Matrix3d RotZ(double deg) {
  return Eigen::AngleAxisd(deg * kRadPerDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

TEST(RotationStatistics, MeanAcrossPlusMinus180DegreesIsNotZero) {
  // 179 and -179 deg about z: the mean is 180 deg (a naive Euler average says 0).
  const auto stats = ComputeRotationStatistics({RotZ(179), RotZ(-179)});
  ASSERT_TRUE(stats.converged);
  EXPECT_LT(LogMatrix(stats.mean.transpose() * RotZ(180)).norm(), 1e-9);
  // Deviations ±1 deg about z: σ_z = sqrt((1 + 1) / (2 - 1)) deg.
  EXPECT_NEAR(stats.sigma.z() / kRadPerDeg, std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(stats.sigma.x(), 0.0, 1e-12);
  EXPECT_NEAR(stats.sigma.y(), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(Euler123FromRotation(stats.mean).z()) / kRadPerDeg, 180.0, 1e-9);
}

TEST(RotationStatistics, HandComputedSingleAxisCase) {
  // 10, 20, 30 deg about x: mean 20 deg, sample σ = 10 deg, covariance 100 deg².
  std::vector<Eigen::Matrix3d> rotations;
  for (double deg : {10.0, 20.0, 30.0}) {
    rotations.push_back(
        Eigen::AngleAxisd(deg * kRadPerDeg, Eigen::Vector3d::UnitX()).toRotationMatrix());
  }
  const auto stats = ComputeRotationStatistics(rotations);
  EXPECT_NEAR(Euler123FromRotation(stats.mean).x() / kRadPerDeg, 20.0, 1e-9);
  EXPECT_NEAR(stats.sigma.x() / kRadPerDeg, 10.0, 1e-9);
  EXPECT_NEAR(stats.covariance(0, 0) / (kRadPerDeg * kRadPerDeg), 100.0, 1e-7);
}

TEST(RotationStatistics, MeanZeroesTheSumOfDeviationsAndIsAMinimum) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.2);
  const Eigen::Matrix3d center = RotationFromEuler123({M_PI, 0.0, -M_PI / 2});  // Husky-like
  std::vector<Eigen::Matrix3d> rotations;
  for (int i = 0; i < 7; ++i) {
    rotations.push_back(center * ExpMatrix({noise(rng), noise(rng), noise(rng)}));
  }
  const auto stats = ComputeRotationStatistics(rotations);
  ASSERT_TRUE(stats.converged);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& xi : stats.deviations) sum += xi;
  EXPECT_LT(sum.norm(), 1e-10);
  auto cost = [&](const Eigen::Matrix3d& c) {
    double total = 0;
    for (const auto& r : rotations) total += LogMatrix(c.transpose() * r).squaredNorm();
    return total;
  };
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d delta = Eigen::Vector3d::Zero();
    delta[axis] = 1e-3;
    EXPECT_GT(cost(stats.mean * ExpMatrix(delta)), cost(stats.mean));
    EXPECT_GT(cost(stats.mean * ExpMatrix(-delta)), cost(stats.mean));
  }
}

TEST(RotationStatistics, SingleRotationHasZeroSpread) {
  const auto stats = ComputeRotationStatistics({RotZ(42)});
  EXPECT_TRUE(stats.mean.isApprox(RotZ(42), 1e-12));
  EXPECT_EQ(stats.sigma, Eigen::Vector3d::Zero());
}

TEST(VectorStatistics, SampleStandardDeviation) {
  const auto stats = ComputeVectorStatistics({{1, 0, 5}, {3, 0, 5}, {5, 0, 5}});
  EXPECT_TRUE(stats.mean.isApprox(Eigen::Vector3d(3, 0, 5)));
  EXPECT_DOUBLE_EQ(stats.sigma.x(), 2.0);
  EXPECT_DOUBLE_EQ(stats.sigma.z(), 0.0);
}

TEST(EulerAngles, Euler123RoundTripAndHuskyPreset) {
  // Husky rig: IMU upside down relative to the LiDAR, Euler [180, 0, -90] deg.
  const Eigen::Matrix3d husky = RotationFromEuler123({180 * kRadPerDeg, 0, -90 * kRadPerDeg});
  EXPECT_TRUE((husky * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE((husky * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), pitch(-1.5, 1.5);
  for (int i = 0; i < 100; ++i) {
    // Drawn z, y, x (tests/testing/random_vector.h).
    const double yaw = angle(rng);
    const double pitch_angle = pitch(rng);
    const double roll = angle(rng);
    const Eigen::Vector3d e(roll, pitch_angle, yaw);
    EXPECT_TRUE(Euler123FromRotation(RotationFromEuler123(e)).isApprox(e, 1e-9)) << e.transpose();
  }
  // Gimbal lock keeps the rotation.
  const Eigen::Matrix3d locked = RotationFromEuler123({0.3, M_PI / 2, 0.5});
  EXPECT_TRUE(RotationFromEuler123(Euler123FromRotation(locked)).isApprox(locked, 1e-9));
}

}  // namespace
}  // namespace tiltcal::geometry
