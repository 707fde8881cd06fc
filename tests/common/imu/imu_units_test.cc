#include "common/imu/imu_units.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/common/imu/synthetic_imu.h"

namespace tiltcal::imu {
namespace {

// 20 s of a tilted IMU turning slowly, 200 Hz, with the first 3 s still.
std::vector<ImuReading> Readings() {
  const auto omega = [](double t) {
    return t < 3.0 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0.05, -0.02, 0.4 * std::sin(t));
  };
  const Eigen::Quaterniond tilt(Eigen::AngleAxisd(0.14, Eigen::Vector3d(1, 0.3, 0).normalized()));
  return testing::SyntheticImu(200.0, 20.0, omega, tilt, Eigen::Vector3d(0, 0, -9.81),
                               Eigen::Vector3d(0.002, -0.001, 0.003), 0.002, 0.03, nullptr);
}

StaticDetectionOptions StaticOptions() {
  StaticDetectionOptions options;
  options.window_s = 0.5;
  options.hop_s = 0.1;
  options.max_gyro_std_radps = 0.01;
  options.max_accel_std_mps2 = 0.05;
  options.max_gyro_mean_radps = 0.05;
  options.min_duration_s = 1.0;
  return options;
}

TEST(DetectAccelUnit, MetresPerSecondSquared) {
  const std::vector<ImuReading> readings = Readings();
  const AccelUnitEvidence evidence =
      DetectAccelUnit(readings, DetectStaticIntervals(readings, StaticOptions()), UnitBand());
  EXPECT_TRUE(evidence.from_static_samples);
  EXPECT_NEAR(evidence.median_norm, 9.81, 0.02);
  ASSERT_TRUE(evidence.unit.has_value());
  EXPECT_EQ(*evidence.unit, AccelUnit::kMetresPerSecond2);
}

TEST(DetectAccelUnit, StandardGravityWithAndWithoutStaticSamples) {
  std::vector<ImuReading> readings = Readings();
  for (ImuReading& r : readings) r.linear_acceleration_mps2 /= kStandardGravityMps2;
  const AccelUnitEvidence evidence = DetectAccelUnit(readings, {}, UnitBand());
  EXPECT_FALSE(evidence.from_static_samples);
  EXPECT_NEAR(evidence.median_norm, 9.81 / kStandardGravityMps2, 0.01);
  ASSERT_TRUE(evidence.unit.has_value());
  EXPECT_EQ(*evidence.unit, AccelUnit::kStandardGravity);
}

TEST(DetectAccelUnit, ImplausibleScaleHasNoUnit) {
  std::vector<ImuReading> readings = Readings();
  for (ImuReading& r : readings) r.linear_acceleration_mps2 *= 100.0;  // cm/s² or a broken driver
  EXPECT_FALSE(DetectAccelUnit(readings, {}, UnitBand()).unit.has_value());
  EXPECT_FALSE(DetectAccelUnit({}, {}, UnitBand()).unit.has_value());
}

TEST(GyroUnitFromScale, RadiansDegreesAndNeither) {
  EXPECT_EQ(GyroUnitFromScale(1.04), GyroUnit::kRadiansPerSecond);
  EXPECT_EQ(GyroUnitFromScale(55.0), GyroUnit::kDegreesPerSecond);
  EXPECT_FALSE(GyroUnitFromScale(3.0).has_value());
  EXPECT_FALSE(GyroUnitFromScale(0.0).has_value());
}

TEST(ConvertToSi, ScalesBothSensors) {
  std::vector<ImuReading> readings(1);
  readings[0].linear_acceleration_mps2 = Eigen::Vector3d(0, 0, 1);
  readings[0].angular_velocity_radps = Eigen::Vector3d(0, 0, 90);
  ConvertToSi(AccelUnit::kStandardGravity, GyroUnit::kDegreesPerSecond, &readings);
  EXPECT_DOUBLE_EQ(readings[0].linear_acceleration_mps2.z(), 9.80665);
  EXPECT_NEAR(readings[0].angular_velocity_radps.z(), M_PI / 2, 1e-15);
  EXPECT_EQ(UnitName(AccelUnit::kStandardGravity), "g");
  EXPECT_EQ(UnitName(GyroUnit::kDegreesPerSecond), "deg/s");
}

}  // namespace
}  // namespace tiltcal::imu
