#include "stages/calibrate/init/hand_eye_rotation.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "tests/stages/calibrate/calibrate_params_text.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::calibrate {
namespace {

using geometry::kRadPerDeg;

// The program's hand-eye settings: at least 15 pairs, excited from 0.02 rad,
// pairs disagreeing by more than 1 deg down-weighted.
proto::HandEyeParams DefaultHandEye() {
  return tiltcal::testing::DefaultCalibrateParamsWith().hand_eye();
}

Eigen::Quaterniond Exp(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  if (theta < 1e-15) return Eigen::Quaterniond::Identity();
  return Eigen::Quaterniond(Eigen::AngleAxisd(theta, phi / theta));
}

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd((a.conjugate() * b).normalized()).angle() / kRadPerDeg;
}

// A rig-like extrinsic: LiDAR mounted upside down and turned (the paper's
// Husky "measured" value is roll 180, yaw -90), plus a few degrees.
Eigen::Quaterniond TrueExtrinsic() {
  return Eigen::Quaterniond(Eigen::AngleAxisd(-88.0 * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(2.5 * kRadPerDeg, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(178.0 * kRadPerDeg, Eigen::Vector3d::UnitX()));
}

// Pairs whose IMU rotation vectors are drawn with per-axis RMS angles
// `axis_rms_rad` (IMU frame), LiDAR rotations C_bl^T C_b C_bl with
// independent measurement noise of `noise_deg` per axis on both.
std::vector<RotationPair> MakePairs(const Eigen::Quaterniond& c_bl, const Eigen::Vector3d& axis_rms_rad,
                                    double noise_deg, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<RotationPair> pairs;
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d phi = axis_rms_rad.cwiseProduct(tiltcal::testing::RandomVector3(n, rng));
    const Eigen::Quaterniond c_b = Exp(phi);
    const Eigen::Quaterniond c_l = c_bl.conjugate() * c_b * c_bl;
    const double s = noise_deg * kRadPerDeg;
    RotationPair p;
    p.imu_delta = c_b * Exp(s * tiltcal::testing::RandomVector3(n, rng));
    p.lidar_delta = c_l * Exp(s * tiltcal::testing::RandomVector3(n, rng));
    pairs.push_back(p);
  }
  return pairs;
}

TEST(HandEyeRotationTest, RecoversKnownRotationWithThreeAxisExcitation) {
  const Eigen::Quaterniond c_bl = TrueExtrinsic();
  const std::vector<RotationPair> pairs =
      MakePairs(c_bl, Eigen::Vector3d(0.15, 0.12, 0.3), /*noise_deg=*/0.05, 60, 11);
  const HandEyeResult r = EstimateHandEyeRotation(pairs, DefaultHandEye());
  ASSERT_TRUE(r.solved);
  EXPECT_TRUE(r.excited) << "excitation " << r.excitation_rad;
  std::printf("hand-eye 3-axis: error %.4f deg, singular values %.3f %.3f %.3f %.5f, excitation %.4f rad\n",
              AngleDeg(r.imu_from_lidar_rotation, c_bl), r.singular_values(0), r.singular_values(1),
              r.singular_values(2), r.singular_values(3), r.excitation_rad);
  EXPECT_LT(AngleDeg(r.imu_from_lidar_rotation, c_bl), 0.1);
  EXPECT_GT(r.excitation_rad, 0.05);
  EXPECT_GT(r.excitation_ratio, 0.2);
  EXPECT_LT(r.singular_values(3), 0.05 * r.singular_values(2));
  EXPECT_LT(r.rms_residual_deg, 0.3);
  EXPECT_EQ(r.num_pairs, 60);
  // Singular values descend.
  for (int i = 0; i < 3; ++i) EXPECT_GE(r.singular_values(i), r.singular_values(i + 1));
  EXPECT_LT(AngleDeg(ChooseInitialRotation(Eigen::Quaterniond::Identity(), r), c_bl), 0.1);
}

TEST(HandEyeRotationTest, ReportsDegeneracyForPlanarMotion) {
  const Eigen::Quaterniond c_bl = TrueExtrinsic();
  // Ground vehicle: yaw about the IMU z axis only (plus noise-level wobble).
  const std::vector<RotationPair> pairs =
      MakePairs(c_bl, Eigen::Vector3d(0.0005, 0.0005, 0.4), /*noise_deg=*/0.05, 60, 12);
  const HandEyeResult r = EstimateHandEyeRotation(pairs, DefaultHandEye());
  ASSERT_TRUE(r.solved);
  EXPECT_FALSE(r.excited) << "excitation " << r.excitation_rad;
  std::printf("hand-eye planar: singular values %.3f %.3f %.5f %.5f, excitation %.5f rad, ratio %.5f\n",
              r.singular_values(0), r.singular_values(1), r.singular_values(2), r.singular_values(3),
              r.excitation_rad, r.excitation_ratio);
  EXPECT_LT(r.excitation_rad, 0.005);
  EXPECT_LT(r.excitation_ratio, 0.02);
  // Motion spread: one dominant axis.
  EXPECT_GT(r.rotation_spread_rad(0), 0.2);
  EXPECT_LT(r.rotation_spread_rad(1), 0.01);
  // The caller keeps the measured value.
  const Eigen::Quaterniond measured =
      c_bl * Exp(Eigen::Vector3d(1.0, -2.0, 0.5) * kRadPerDeg);
  EXPECT_LT(AngleDeg(ChooseInitialRotation(measured, r), measured), 1e-9);
}

TEST(HandEyeRotationTest, DownWeightsInconsistentPairs) {
  const Eigen::Quaterniond c_bl = TrueExtrinsic();
  std::vector<RotationPair> pairs = MakePairs(c_bl, Eigen::Vector3d(0.15, 0.12, 0.3), 0.05, 40, 13);
  // Five gross odometry failures: LiDAR deltas rotated by ~20 deg.
  for (int i = 0; i < 5; ++i) {
    pairs[static_cast<std::size_t>(7 * i)].lidar_delta =
        pairs[static_cast<std::size_t>(7 * i)].lidar_delta * Exp(Eigen::Vector3d(0.35, 0.0, 0.0));
  }
  const HandEyeResult r = EstimateHandEyeRotation(pairs, DefaultHandEye());
  ASSERT_TRUE(r.solved);
  const proto::HandEyeParams unweighted =  // every pair weight 1
      tiltcal::testing::DefaultCalibrateParamsWith("hand_eye { consistent_angle_deg: 180 }")
          .hand_eye();
  const HandEyeResult plain = EstimateHandEyeRotation(pairs, unweighted);
  const double weighted_deg = AngleDeg(r.imu_from_lidar_rotation, c_bl);
  const double plain_deg = AngleDeg(plain.imu_from_lidar_rotation, c_bl);
  std::printf("hand-eye with 5/40 gross outliers: %.3f deg weighted, %.3f deg unweighted\n", weighted_deg, plain_deg);
  EXPECT_LT(weighted_deg, 1.0);
  EXPECT_LT(weighted_deg, 0.5 * plain_deg);
}

TEST(HandEyeRotationTest, NeedsEnoughPairsAndBuildsPairsFromTrajectories) {
  const Eigen::Quaterniond c_bl = TrueExtrinsic();
  EXPECT_FALSE(EstimateHandEyeRotation(MakePairs(c_bl, Eigen::Vector3d::Constant(0.2), 0.0, 10, 14),
                                       DefaultHandEye())
                   .solved);
  // Absolute trajectories: C_ab(t_k) and C_{l0 lk} = C_bl^T C_ab(t_0)^T C_ab(t_k) C_bl.
  std::vector<Eigen::Quaterniond> imu, lidar;
  for (int k = 0; k < 100; ++k) {
    const double t = 0.1 * k;
    const Eigen::Quaterniond c_ab =
        Exp(Eigen::Vector3d(0.3 * std::sin(0.7 * t), 0.25 * std::sin(1.1 * t + 0.4), 0.9 * std::sin(0.3 * t)));
    imu.push_back(c_ab);
  }
  for (int k = 0; k < 100; ++k) lidar.push_back(c_bl.conjugate() * imu[0].conjugate() * imu[static_cast<std::size_t>(k)] * c_bl);
  const std::vector<RotationPair> pairs = MakeRotationPairs(imu, lidar, 5);
  ASSERT_EQ(pairs.size(), 19u);
  const HandEyeResult r = EstimateHandEyeRotation(pairs, DefaultHandEye());
  ASSERT_TRUE(r.solved);
  EXPECT_TRUE(r.excited);
  EXPECT_LT(AngleDeg(r.imu_from_lidar_rotation, c_bl), 1e-6);
  EXPECT_TRUE(MakeRotationPairs(imu, {}, 5).empty());
}

}  // namespace
}  // namespace tiltcal::calibrate
