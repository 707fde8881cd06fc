#include "common/imu/static_detection.h"

#include <gtest/gtest.h>

#include "tests/common/imu/synthetic_imu.h"

namespace tiltcal::imu {
namespace {

// Still for [0, 3) s, turning for [3, 6) s, still for [6, 8) s, turning after.
Eigen::Vector3d Omega(double t) {
  const bool moving = (t >= 3.0 && t < 6.0) || t >= 8.0;
  return moving ? Eigen::Vector3d(0.1, -0.2, 0.5 + 0.3 * std::sin(3 * t)) : Eigen::Vector3d::Zero();
}

TEST(StaticDetection, FindsEveryStillIntervalWithItsMeans) {
  const Eigen::Vector3d bias(0.002, -0.001, 0.003);
  const auto readings = testing::SyntheticImu(200, 10, Omega, Eigen::Quaterniond::Identity(),
                                              {0, 0, -9.81}, bias, 0.001, 0.01, nullptr);
  StaticDetectionOptions options;
  const auto intervals = DetectStaticIntervals(readings, options);
  ASSERT_EQ(intervals.size(), 2u);
  EXPECT_NEAR(intervals[0].begin_s, 0.0, 1e-9);
  EXPECT_NEAR(intervals[0].end_s, 3.0, options.hop_s + 0.01);
  EXPECT_LE(intervals[0].end_s, 3.0 + 1e-9);
  EXPECT_GE(intervals[1].begin_s, 6.0 - 1e-9);
  EXPECT_NEAR(intervals[1].begin_s, 6.0, options.hop_s + 0.01);
  EXPECT_NEAR(intervals[1].end_s, 8.0, options.hop_s + 0.01);
  // Mean gyro = bias within noise / sqrt(n); mean accel = −g.
  EXPECT_LT((intervals[0].mean_gyro_radps - bias).norm(), 3e-4);
  EXPECT_LT((intervals[0].mean_accel_mps2 - Eigen::Vector3d(0, 0, 9.81)).norm(), 3e-3);
  EXPECT_NEAR(intervals[0].accel_std_mps2, 0.01, 0.002);

  const StaticInterval start = DetectStaticStart(readings, options);
  ASSERT_TRUE(start.found);
  EXPECT_EQ(start.begin_index, 0u);
  EXPECT_EQ(start.end_index, intervals[0].end_index);
}

TEST(StaticDetection, NoStaticStartWhenMovingFromTheBeginning) {
  const auto readings = testing::SyntheticImu(
      200, 4, [](double) { return Eigen::Vector3d(0, 0, 0.3); }, Eigen::Quaterniond::Identity(),
      {0, 0, -9.81}, Eigen::Vector3d::Zero(), 0.001, 0.01, nullptr);
  EXPECT_TRUE(DetectStaticIntervals(readings, {}).empty());  // steady turn is not still
  EXPECT_FALSE(DetectStaticStart(readings, {}).found);
}

TEST(StaticDetection, ShortStillnessIsIgnored) {
  const auto readings = testing::SyntheticImu(
      200, 4, [](double t) { return t < 0.7 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0, 0, 1); },
      Eigen::Quaterniond::Identity(), {0, 0, -9.81}, Eigen::Vector3d::Zero(), 0.001, 0.01,
      nullptr);
  EXPECT_FALSE(DetectStaticStart(readings, {}).found);
}

TEST(ImuReadings, ValidationNamesTheSample) {
  std::vector<ImuReading> readings(3);
  readings[1].time_s = 0.1;
  readings[2].time_s = 0.1;
  const Status status = ValidateImuReadings(readings);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("IMU sample 2"), std::string::npos) << status.message();
  readings[2].time_s = 0.2;
  readings[1].angular_velocity_radps.x() = NAN;
  EXPECT_NE(ValidateImuReadings(readings).message().find("IMU sample 1: non-finite"),
            std::string::npos);
}

}  // namespace
}  // namespace tiltcal::imu
