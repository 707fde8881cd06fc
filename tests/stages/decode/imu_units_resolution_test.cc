#include "stages/decode/imu_units_resolution.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "stages/decode/decode_params.h"
#include "stages/decode/default_params_text.h"
#include "tests/stages/decode/vehicle_bag.h"
#include "tests/testing/params_text.h"

namespace tiltcal::decode {
namespace {

proto::DecodeParams DefaultParams() {
  return testing::DefaultParamsWith<proto::DecodeParams>(DefaultParamsText(), "");
}

std::string AllNotes(const ImuUnitsResolution& resolution) {
  std::string text;
  for (const std::string& note : resolution.notes) text += note + "\n";
  return text;
}

TEST(DecodeParams, DefaultsAreValid) {
  const Status status = ValidateDecodeParams(DefaultParams());
  EXPECT_TRUE(status.ok()) << status.message();
}

TEST(DecodeParams, AccelerometerBandMustBeOpen) {
  proto::DecodeParams params = DefaultParams();
  params.mutable_imu_units()->set_accel_norm_ratio_min(1.0);
  params.mutable_imu_units()->set_accel_norm_ratio_max(1.0);
  EXPECT_EQ(ValidateDecodeParams(params).message(),
            "field imu_units.accel_norm_ratio_max must be greater than "
            "imu_units.accel_norm_ratio_min");
}

// An IMU whose rates are too fast even in deg/s (mrad/s, or a broken
// driver): neither unit fits, an error naming the value.
TEST(ResolveImuUnits, GyroFittingNeitherUnitIsAnError) {
  std::vector<imu::ImuReading> readings = testing::VehicleBagImu(12.0);
  for (imu::ImuReading& r : readings) r.angular_velocity_radps *= 1000.0;
  ImuUnitsResolution resolution;
  const Status status = ResolveImuUnits(readings, proto::Rig(), {"a.bag", ""},
                                        DefaultParams().imu_units(), &resolution);
  ASSERT_FALSE(status.ok());
  // The rate is printed with 4 significant digits; it lies near 603.95, where
  // the last digit depends on the compiler's floating point, so it is parsed.
  const std::string& m = status.message();
  const std::string prefix = "a.bag: the gyro fits neither rad/s nor deg/s: |ω| at percentile 99 is ";
  ASSERT_EQ(m.substr(0, prefix.size()), prefix) << m;
  EXPECT_NEAR(std::stod(m.substr(prefix.size())), 603.9, 0.15) << m;
  EXPECT_NE(m.find(", above 5 rad/s, the fastest turn of a ground vehicle, and even 60"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find(" deg/s is 10.54 rad/s (imu_units.max_vehicle_turn_rate_radps of the decode "
                   "params)"),
            std::string::npos)
      << m;
}

// An IMU mounted z-down (an FRD frame, f = (0, 0, −9.81) at rest) under a
// LiDAR mounted upright, declared by the rig's rotation: the LiDAR's +z is
// the IMU's −z, the sign is right, no warning. The rig of README.md.
TEST(ResolveImuUnits, ZDownImuDeclaredByTheRigPassesTheSignCheck) {
  std::vector<imu::ImuReading> readings = testing::VehicleBagImu(12.0);
  for (imu::ImuReading& r : readings) {
    r.linear_acceleration_mps2 = Eigen::Vector3d(r.linear_acceleration_mps2.x(),
                                                 -r.linear_acceleration_mps2.y(),
                                                 -r.linear_acceleration_mps2.z());
  }
  const proto::Rig rig = testing::ParamsFromText<proto::Rig>(
      "imu_from_lidar { rotation { w: 0 x: -0.70710678118654752 y: 0.70710678118654752 z: 0 } }");
  ImuUnitsResolution resolution;
  Status status = ResolveImuUnits(readings, rig, {"a.bag", "rig.txtpb"},
                                  DefaultParams().imu_units(), &resolution);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(resolution.warnings.empty()) << AllNotes(resolution);
  EXPECT_NE(AllNotes(resolution).find("points 0.0 deg from the LiDAR's +z"), std::string::npos)
      << AllNotes(resolution);
  // The same IMU with a rig that says nothing of the mounting: a warning.
  status = ResolveImuUnits(readings,
                           testing::ParamsFromText<proto::Rig>("imu_from_lidar { rotation { w: 1 } }"),
                           {"a.bag", "rig.txtpb"}, DefaultParams().imu_units(), &resolution);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(resolution.warnings.size(), 1u);
  EXPECT_NE(resolution.warnings[0].find("an IMU mounted upside down and not declared"),
            std::string::npos);
}

// A specific force whose mean has no clear direction (here: every other
// sample flipped) is not used for the sign; said so. The flips are at the
// Nyquist frequency, which the static detection's low-pass removes: the
// still start is found, and its mean force is near zero.
TEST(ResolveImuUnits, MeanForceWithoutDirectionIsNotChecked) {
  std::vector<imu::ImuReading> readings = testing::VehicleBagImu(12.0);
  for (size_t i = 0; i < readings.size(); i += 2) readings[i].linear_acceleration_mps2 *= -1.0;
  proto::DecodeParams params = DefaultParams();
  ImuUnitsResolution resolution;
  const Status status = ResolveImuUnits(
      readings, testing::ParamsFromText<proto::Rig>("imu_from_lidar { rotation { w: 1 } }"),
      {"a.bag", "rig.txtpb"}, params.imu_units(), &resolution);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(resolution.warnings.empty());
  EXPECT_NE(AllNotes(resolution).find("accelerometer sign not checked: the mean specific force "
                                      "over 410 static samples is 0.00"),
            std::string::npos)
      << AllNotes(resolution);
  EXPECT_NE(AllNotes(resolution).find("(no clear direction at rest)"), std::string::npos)
      << AllNotes(resolution);
  // On the readings as recorded no interval is still; the mean is taken over all.
  params.mutable_imu_units()->mutable_static_detection()->clear_low_pass();
  ASSERT_TRUE(ResolveImuUnits(readings,
                              testing::ParamsFromText<proto::Rig>("imu_from_lidar { rotation { w: 1 } }"),
                              {"a.bag", "rig.txtpb"}, params.imu_units(), &resolution)
                  .ok());
  EXPECT_NE(AllNotes(resolution).find("accelerometer sign not checked: the mean specific force "
                                      "over all 2401 samples (no static interval) is"),
            std::string::npos)
      << AllNotes(resolution);
}

}  // namespace
}  // namespace tiltcal::decode
