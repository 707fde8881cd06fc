#include "common/io/rig.h"

#include <cmath>

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

constexpr char kRig[] = R"(
imu_from_lidar {
  rotation { w: 0.0 x: -0.7071 y: 0.7071 z: 0.0 }
  translation { x: 0.25 y: -0.07 z: -0.46 }
}
imu_height_m: 0.30
gravity_flat_in_imu { x: 0 y: 0 z: 9.81 }
)";

Status LoadFromText(const std::string& text, proto::Rig* rig) {
  testing::TempDir dir;
  const std::string path = dir.File("rig.txtpb");
  EXPECT_TRUE(WriteFileAtomically(path, text).ok());
  return LoadRig(path, rig);
}

std::string LoadError(const std::string& text) {
  proto::Rig rig;
  const Status status = LoadFromText(text, &rig);
  EXPECT_FALSE(status.ok()) << text;
  EXPECT_NE(status.message().find("rig.txtpb: "), std::string::npos) << status.message();
  return status.message();
}

TEST(LoadRig, HandWrittenQuaternionIsNormalised) {
  proto::Rig rig;
  const Status status = LoadFromText(kRig, &rig);
  ASSERT_TRUE(status.ok()) << status.message();
  const auto& q = rig.imu_from_lidar().rotation();
  EXPECT_NEAR(q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z(), 1.0, 1e-15);
  EXPECT_NEAR(q.y(), std::sqrt(0.5), 1e-12);
  EXPECT_DOUBLE_EQ(rig.imu_from_lidar().translation().z(), -0.46);
}

TEST(LoadRig, NonUnitQuaternionIsAnError) {
  const std::string error =
      LoadError("imu_from_lidar { rotation { w: 2 } translation { x: 0.1 } }");
  EXPECT_NE(error.find("imu_from_lidar.rotation is not a unit quaternion (norm 2"),
            std::string::npos)
      << error;
}

TEST(LoadRig, ZeroRotationIsAnError) {
  EXPECT_NE(LoadError("imu_from_lidar { rotation { w: 0 } }").find("not a unit quaternion"),
            std::string::npos);
}

// A dataset rig may leave the extrinsic out (tiltcal_initial_extrinsic finds
// it); the stages that need it refuse a rig without it, naming the stage
// that writes the sequence's rig.
TEST(LoadRig, ExtrinsicIsOptionalButRequiredWhereItIsUsed) {
  proto::Rig rig;
  EXPECT_TRUE(LoadFromText("imu_height_m: 0.3", &rig).ok());
  EXPECT_FALSE(rig.has_imu_from_lidar());
  testing::TempDir dir;
  const std::string path = dir.File("rig.txtpb");
  ASSERT_TRUE(WriteFileAtomically(path, "imu_height_m: 0.3").ok());
  const Status status = LoadRigWithExtrinsic(path, &rig);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("rig.txtpb: imu_from_lidar.rotation is missing"),
            std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("tiltcal_initial_extrinsic"), std::string::npos)
      << status.message();
  ASSERT_TRUE(WriteFileAtomically(path, "imu_from_lidar { rotation { w: 1 } }").ok());
  EXPECT_TRUE(LoadRigWithExtrinsic(path, &rig).ok());
}

TEST(LoadRig, NonFiniteAndOutOfBoundValuesNameTheField) {
  EXPECT_NE(LoadError("imu_from_lidar { rotation { w: 1 } translation { x: nan } }")
                .find("imu_from_lidar.translation is not finite"),
            std::string::npos);
  EXPECT_NE(LoadError("imu_from_lidar { rotation { w: 1 } translation { x: 30 } }")
                .find("imu_from_lidar.translation is 30 m long"),
            std::string::npos);
  EXPECT_NE(LoadError("imu_from_lidar { rotation { w: 1 } } imu_height_m: -0.3")
                .find("imu_height_m = -0.3 is outside"),
            std::string::npos);
  EXPECT_NE(LoadError("imu_from_lidar { rotation { w: 1 } } gravity_flat_in_imu { z: 1.0 }")
                .find("gravity_flat_in_imu has norm 1,"),
            std::string::npos);
}

TEST(LoadRig, ImuUnitsByName) {
  proto::Rig rig;
  Status status = LoadFromText(std::string(kRig) + "imu_accel_unit: G imu_gyro_unit: DEGPS", &rig);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(rig.imu_accel_unit(), proto::AccelUnit::G);
  EXPECT_EQ(rig.imu_gyro_unit(), proto::GyroUnit::DEGPS);
  status = LoadFromText(kRig, &rig);  // not stated: AUTO
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(rig.imu_accel_unit(), proto::AccelUnit::AUTO);
  EXPECT_EQ(rig.imu_gyro_unit(), proto::GyroUnit::AUTO);
}

TEST(LoadRig, UnknownImuUnitIsAnError) {
  EXPECT_NE(LoadError(std::string(kRig) + "imu_accel_unit: MPS").find("imu_accel_unit"),
            std::string::npos);
  // Text format takes any number for a proto3 enum; the rig does not.
  EXPECT_NE(LoadError(std::string(kRig) + "imu_accel_unit: 7")
                .find("imu_accel_unit = 7 is not one of AUTO, MPS2, G"),
            std::string::npos);
  EXPECT_NE(LoadError(std::string(kRig) + "imu_gyro_unit: 3")
                .find("imu_gyro_unit = 3 is not one of AUTO, RADPS, DEGPS"),
            std::string::npos);
}

TEST(LoadRig, DirectoryAndEmptyFileAreErrors) {
  testing::TempDir dir;
  proto::Rig rig;
  const Status directory = LoadRig(dir.path(), &rig);
  ASSERT_FALSE(directory.ok());
  EXPECT_NE(directory.message().find("not a regular file"), std::string::npos)
      << directory.message();
  const std::string empty = dir.File("rig.txtpb");
  ASSERT_TRUE(WriteFileAtomically(empty, "\n").ok());
  const Status status = LoadRig(empty, &rig);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(), empty + ": empty file (a Rig in text format is expected)");
  EXPECT_FALSE(LoadRig(dir.File("missing.txtpb"), &rig).ok());
}

}  // namespace
}  // namespace tiltcal
