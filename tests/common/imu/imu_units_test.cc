#include "common/imu/imu_units.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/common/imu/imu_test_options.h"
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

TEST(DetectAccelUnit, MetresPerSecondSquared) {
  const std::vector<ImuReading> readings = Readings();
  const AccelUnitEvidence evidence = DetectAccelUnit(
      readings, DetectStaticIntervals(readings, testing::StaticDetectionTestOptions()), UnitBand());
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

// The band decides: a norm of 11.5 is m/s² with the default band (up to
// 1.25 g) and nothing with a narrower one.
TEST(DetectAccelUnit, BandFromTheCaller) {
  std::vector<ImuReading> readings = Readings();
  for (ImuReading& r : readings) r.linear_acceleration_mps2 *= 11.5 / 9.81;
  EXPECT_EQ(DetectAccelUnit(readings, {}, UnitBand()).unit, AccelUnit::kMetresPerSecond2);
  EXPECT_FALSE(DetectAccelUnit(readings, {}, UnitBand{0.9, 1.1}).unit.has_value());
  EXPECT_EQ(DetectAccelUnit(readings, {}, UnitBand()).num_samples, readings.size());
}

// Readings() turns at up to 0.4 rad/s: rad/s, as published; the same in
// deg/s (22.9) is above the 5 rad/s no ground vehicle reaches.
TEST(DetectGyroUnitFromRates, RadiansAssumedDegreesDetected) {
  std::vector<ImuReading> readings = Readings();
  const GyroRateEvidence radians = DetectGyroUnitFromRates(readings, 99.0, 5.0);
  EXPECT_EQ(radians.unit, GyroUnit::kRadiansPerSecond);
  EXPECT_EQ(radians.percentile, 99.0);
  EXPECT_NEAR(radians.rate_at_percentile, 0.4, 0.02);
  for (ImuReading& r : readings) r.angular_velocity_radps /= kRadiansPerDegree;
  const GyroRateEvidence degrees = DetectGyroUnitFromRates(readings, 99.0, 5.0);
  EXPECT_EQ(degrees.unit, GyroUnit::kDegreesPerSecond);
  EXPECT_NEAR(degrees.rate_at_percentile, 0.4 / kRadiansPerDegree, 1.0);
  // The percentile: the median |ω| of a sequence that stands still for 3 s
  // of 20 and then turns at |0.4 sin t| is well below its 99th percentile.
  EXPECT_LT(DetectGyroUnitFromRates(readings, 50.0, 5.0).rate_at_percentile,
            0.8 * degrees.rate_at_percentile);
}

TEST(DetectGyroUnitFromRates, NeitherUnitFitsATooFastGyro) {
  std::vector<ImuReading> readings = Readings();
  // 0.4 rad/s published in mrad/s: 400, i.e. 7 rad/s even when read as deg/s.
  for (ImuReading& r : readings) r.angular_velocity_radps *= 1000.0;
  EXPECT_FALSE(DetectGyroUnitFromRates(readings, 99.0, 5.0).unit.has_value());
  // No samples: rate 0, rad/s assumed.
  EXPECT_EQ(DetectGyroUnitFromRates({}, 99.0, 5.0).unit, GyroUnit::kRadiansPerSecond);
}

// At rest the specific force points up: +z of a level z-up IMU, tilted by
// the start attitude of Readings() (0.14 rad).
TEST(MeanRestForce, StaticSamplesElseAll) {
  const std::vector<ImuReading> readings = Readings();
  const RestForce rest = MeanRestForce(
      readings, DetectStaticIntervals(readings, testing::StaticDetectionTestOptions()));
  EXPECT_TRUE(rest.from_static_samples);
  EXPECT_GT(rest.num_samples, 350u);  // about 3 s at 200 Hz
  EXPECT_LT(rest.num_samples, 700u);
  EXPECT_NEAR(rest.mean.norm(), 9.81, 0.01);
  EXPECT_NEAR(std::acos(rest.mean.normalized().z()), 0.14, 0.01);
  const RestForce all = MeanRestForce(readings, {});
  EXPECT_FALSE(all.from_static_samples);
  EXPECT_EQ(all.num_samples, readings.size());
  EXPECT_GT(all.mean.normalized().z(), 0.9);  // the turning IMU stays near upright
  EXPECT_EQ(MeanRestForce({}, {}).num_samples, 0u);
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
