#include "stages/gravity/gravity.h"

#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <filesystem>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "stages/gravity/default_params_text.h"
#include "tests/common/imu/synthetic_imu.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/imu.pb.h"

namespace tiltcal::gravity {
namespace {

using geometry::kRadPerDeg;
const Eigen::Vector3d kGravityWorld(0, 0, -9.81);

// The shipped defaults (stages/gravity/default_params.txtpb, compiled in).
proto::GravityParams DefaultParams() {
  return testing::DefaultParamsWith<proto::GravityParams>(DefaultParamsText());
}

// A vehicle on a plane tilted by `tilt_deg` about x: still for 2 s, then
// turning about the plane normal, still again at 8..10 s. The IMU is mounted
// with C_vb (vehicle from IMU); the LiDAR with C_bl. One ground plane per
// 0.1 s, the plane normal seen in the LiDAR frame.
struct Scenario {
  Eigen::Quaterniond c_vb{Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                          Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())};
  Eigen::Quaterniond c_bl{Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                          Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ())};
  GravityInputs inputs;

  explicit Scenario(double tilt_deg) {
    const Eigen::Quaterniond tilt(
        Eigen::AngleAxisd(tilt_deg * kRadPerDeg, Eigen::Vector3d::UnitX()));
    const Eigen::Vector3d yaw_axis_in_imu = c_vb.conjugate() * Eigen::Vector3d::UnitZ();
    auto omega = [&](double t) -> Eigen::Vector3d {
      const bool moving = t >= 2.0 && t < 8.0;
      return moving ? Eigen::Vector3d(yaw_axis_in_imu * (0.5 + 0.3 * std::sin(t)))
                    : Eigen::Vector3d::Zero();
    };
    inputs.imu = imu::testing::SyntheticImu(200, 12, omega, tilt * c_vb, kGravityWorld,
                                            Eigen::Vector3d(0.002, 0, -0.001), 0.001, 0.02,
                                            nullptr);
    inputs.first_imu_stamp_ns = 1'000'000'000'000;
    Rigid3d extrinsic;
    extrinsic.rotation = c_bl;
    *inputs.rig.mutable_imu_from_lidar() = ToProto(extrinsic);
    const Eigen::Vector3d normal_in_lidar = c_bl.conjugate() * yaw_axis_in_imu;
    for (int k = 0; k < 110; ++k) {
      proto::GroundPlane plane;
      plane.set_stamp_ns(inputs.first_imu_stamp_ns + k * 100'000'000LL);
      plane.set_valid(k % 10 != 3);  // some rejected scans
      *plane.mutable_normal_in_lidar() = ToProto(normal_in_lidar);
      plane.set_height_m(1.0);
      inputs.ground.push_back(plane);
    }
  }
  // Gravity in the IMU frame when the vehicle stands on level ground.
  Eigen::Vector3d FlatGravityInImu() const { return c_vb.conjugate() * kGravityWorld; }
};

TEST(Gravity, LevelSequenceGivesFlatGravityFromStaticWindows) {
  Scenario scenario(0.0);
  proto::GravityReference out;
  ASSERT_TRUE(EstimateGravityReference(scenario.inputs, DefaultParams(), &out).ok());
  EXPECT_TRUE(out.is_level()) << out.level_statistic();
  EXPECT_LT(out.level_statistic_deg(), 0.2);
  EXPECT_EQ(out.static_windows_size(), 2);
  ASSERT_TRUE(out.has_gravity_flat());
  EXPECT_EQ(out.gravity_flat_source(), "static_windows");
  const double error_deg =
      std::acos(ToEigen(out.gravity_flat_in_imu()).normalized().dot(
          scenario.FlatGravityInImu().normalized())) /
      kRadPerDeg;
  EXPECT_LT(error_deg, 0.05);
  ASSERT_EQ(out.inclination_size(), 110);
  for (const auto& sample : out.inclination()) {
    ASSERT_TRUE(sample.has_inclination_deg());
    EXPECT_LT(sample.inclination_deg(), 0.3);
  }
  EXPECT_FALSE(out.inclination(3).has_ground_slope_deg());  // rejected plane
}

// An idling engine the IMU feels all along: 0.3 m/s² and 0.02 rad/s at
// 25.3 Hz on every axis.
void AddEngineVibration(std::vector<imu::ImuReading>* readings) {
  const double w = 2.0 * M_PI * 25.3;
  for (imu::ImuReading& r : *readings) {
    const Eigen::Vector3d wave(std::sin(w * r.time_s), std::cos(w * r.time_s),
                               std::sin(w * r.time_s + 1.0));
    r.linear_acceleration_mps2 += 0.3 * wave;
    r.angular_velocity_radps += 0.02 * wave;
  }
}

TEST(Gravity, VibratingImuKeepsItsStaticWindowsGyroBiasAndFlatGravity) {
  Scenario scenario(0.0);
  AddEngineVibration(&scenario.inputs.imu);
  proto::GravityParams recorded = DefaultParams();
  recorded.mutable_static_detection()->clear_low_pass();
  proto::GravityReference unfiltered;
  ASSERT_TRUE(EstimateGravityReference(scenario.inputs, recorded, &unfiltered).ok());
  EXPECT_EQ(unfiltered.static_windows_size(), 0);  // what the low-pass is for

  proto::GravityReference out;
  ASSERT_TRUE(EstimateGravityReference(scenario.inputs, DefaultParams(), &out).ok());
  EXPECT_EQ(out.static_windows_size(), 2);
  EXPECT_LT((ToEigen(out.gyro_bias_radps()) - Eigen::Vector3d(0.002, 0, -0.001)).norm(), 3e-4);
  EXPECT_TRUE(out.is_level()) << out.level_statistic();
  EXPECT_LT(out.level_statistic_deg(), 0.2);
  ASSERT_EQ(out.gravity_flat_source(), "static_windows");
  const double error_deg =
      std::acos(ToEigen(out.gravity_flat_in_imu()).normalized().dot(
          scenario.FlatGravityInImu().normalized())) /
      kRadPerDeg;
  EXPECT_LT(error_deg, 0.05);
}

TEST(Gravity, FlatCalibrationIsPreferredAndDisagreementReported) {
  Scenario scenario(0.0);
  proto::CalibrationResult calibration;
  const Eigen::Vector3d tilted_by_1deg =
      Eigen::AngleAxisd(1.0 * kRadPerDeg, Eigen::Vector3d::UnitY()) * scenario.FlatGravityInImu();
  *calibration.mutable_gravity_in_world() = ToProto(tilted_by_1deg);
  scenario.inputs.flat_calibration = &calibration;
  proto::GravityReference out;
  ASSERT_TRUE(EstimateGravityReference(scenario.inputs, DefaultParams(), &out).ok());
  EXPECT_EQ(out.gravity_flat_source(), "both");
  EXPECT_TRUE(ToEigen(out.gravity_flat_in_imu()).isApprox(tilted_by_1deg));
  EXPECT_NEAR(out.sources_disagreement_deg(), 1.0, 0.05);
}

TEST(Gravity, TiltedSequenceMeasuresInclinationAgainstTheDatasetReference) {
  Scenario scenario(8.0);
  scenario.inputs.dataset_reference.set_has_gravity_flat(true);
  *scenario.inputs.dataset_reference.mutable_gravity_flat_in_imu() =
      ToProto(scenario.FlatGravityInImu());
  scenario.inputs.dataset_reference_source = "rig";
  proto::GravityReference out;
  ASSERT_TRUE(EstimateGravityReference(scenario.inputs, DefaultParams(), &out).ok());
  EXPECT_FALSE(out.is_level());
  EXPECT_NEAR(out.level_statistic_deg(), 8.0, 0.2);
  EXPECT_EQ(out.gravity_flat_source(), "rig");
  for (const auto& sample : out.inclination()) {
    EXPECT_NEAR(sample.inclination_deg(), 8.0, 0.3);
  }
}

TEST(Gravity, TiltedSequenceWithoutReferenceHasNoFlatGravity) {
  Scenario scenario(8.0);
  proto::GravityReference out;
  ASSERT_TRUE(EstimateGravityReference(scenario.inputs, DefaultParams(), &out).ok());
  EXPECT_FALSE(out.is_level());
  EXPECT_FALSE(out.has_gravity_flat());
  EXPECT_FALSE(out.inclination(0).has_inclination_deg());
  EXPECT_NEAR(out.inclination(0).ground_slope_deg(), 8.0, 0.2);
}

TEST(Gravity, RunWritesTheReferenceAndFailsCleanlyOnBadInputs) {
  testing::TempDir dir;
  Scenario scenario(8.0);
  {
    RecordWriter imu_writer;
    ASSERT_TRUE(imu_writer.Open(dir.File("imu.binpb"), "tiltcal.proto.ImuSample", {}, false).ok());
    for (const auto& reading : scenario.inputs.imu) {
      proto::ImuSample sample;
      sample.set_stamp_ns(scenario.inputs.first_imu_stamp_ns + std::llround(reading.time_s * 1e9));
      *sample.mutable_angular_velocity_radps() = ToProto(reading.angular_velocity_radps);
      *sample.mutable_linear_acceleration_mps2() = ToProto(reading.linear_acceleration_mps2);
      ASSERT_TRUE(imu_writer.Write(sample).ok());
    }
    ASSERT_TRUE(imu_writer.Close().ok());
    RecordWriter ground_writer;
    ASSERT_TRUE(
        ground_writer.Open(dir.File("ground.binpb"), "tiltcal.proto.GroundPlane", {}, false).ok());
    for (const auto& plane : scenario.inputs.ground) ASSERT_TRUE(ground_writer.Write(plane).ok());
    ASSERT_TRUE(ground_writer.Close().ok());
  }
  proto::Rig rig = scenario.inputs.rig;
  rig.set_gravity_reference("flat/gravity.txtpb");
  ASSERT_TRUE(WriteTextProto(dir.File("rig.txtpb"), rig).ok());
  GravityPaths paths;
  paths.imu = dir.File("imu.binpb");
  paths.ground = dir.File("ground.binpb");
  paths.rig = dir.File("rig.txtpb");
  paths.out = dir.File("gravity.txtpb");

  // The reference named by the rig does not exist yet.
  Status status = gravity::Run(paths, DefaultParams(), nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("flat/gravity.txtpb"), std::string::npos) << status.message();
  EXPECT_FALSE(testing::FileExists(paths.out));

  std::filesystem::create_directory(dir.File("flat"));
  proto::GravityReference flat;
  flat.set_has_gravity_flat(true);
  *flat.mutable_gravity_flat_in_imu() = ToProto(scenario.FlatGravityInImu());
  ASSERT_TRUE(WriteTextProto(dir.File("flat/gravity.txtpb"), flat).ok());
  status = gravity::Run(paths, DefaultParams(), nullptr);
  ASSERT_TRUE(status.ok()) << status.message();
  proto::GravityReference out;
  ASSERT_TRUE(ReadTextProto(paths.out, &out).ok());
  EXPECT_EQ(out.gravity_flat_source(), "reference flat/gravity.txtpb");
  EXPECT_EQ(out.provenance().producer(), "tiltcal_gravity");
  EXPECT_NEAR(out.inclination(50).inclination_deg(), 8.0, 0.3);

  // A reference whose g_f is not finite or not a gravity is an error naming
  // the file (it used to be taken as it was).
  for (const Eigen::Vector3d& bad :
       {Eigen::Vector3d(0, 0, std::numeric_limits<double>::infinity()), Eigen::Vector3d(0, 0, 1.5),
        Eigen::Vector3d(0, std::nan(""), 9.81)}) {
    proto::GravityReference broken = flat;
    *broken.mutable_gravity_flat_in_imu() = ToProto(bad);
    ASSERT_TRUE(WriteTextProto(dir.File("flat/gravity.txtpb"), broken).ok());
    status = gravity::Run(paths, DefaultParams(), nullptr);
    ASSERT_FALSE(status.ok()) << bad.transpose();
    EXPECT_EQ(status.message().rfind(dir.File("flat/gravity.txtpb") + ": gravity_flat_in_imu", 0), 0u)
        << status.message();
  }
  ASSERT_TRUE(WriteTextProto(dir.File("flat/gravity.txtpb"), flat).ok());

  // A rig without the measured extrinsic is an error naming the field.
  proto::Rig no_extrinsic = rig;
  no_extrinsic.mutable_imu_from_lidar()->clear_rotation();
  ASSERT_TRUE(WriteTextProto(dir.File("rig.txtpb"), no_extrinsic).ok());
  status = gravity::Run(paths, DefaultParams(), nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("imu_from_lidar.rotation"), std::string::npos)
      << status.message();

  paths.imu = dir.File("missing.binpb");
  status = gravity::Run(paths, DefaultParams(), nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("missing.binpb"), std::string::npos);
}

// Ground planes with a NaN or zero normal, and a flat calibration without a
// gravity: errors naming the file and the record or field, no output.
TEST(Gravity, NanOrZeroNormalsAndACalibrationWithoutGravityAreRefused) {
  testing::TempDir dir;
  Scenario scenario(0.0);
  {
    RecordWriter imu_writer;
    ASSERT_TRUE(imu_writer.Open(dir.File("imu.binpb"), "tiltcal.proto.ImuSample", {}, false).ok());
    for (const auto& reading : scenario.inputs.imu) {
      proto::ImuSample sample;
      sample.set_stamp_ns(scenario.inputs.first_imu_stamp_ns + std::llround(reading.time_s * 1e9));
      *sample.mutable_angular_velocity_radps() = ToProto(reading.angular_velocity_radps);
      *sample.mutable_linear_acceleration_mps2() = ToProto(reading.linear_acceleration_mps2);
      ASSERT_TRUE(imu_writer.Write(sample).ok());
    }
    ASSERT_TRUE(imu_writer.Close().ok());
  }
  ASSERT_TRUE(WriteTextProto(dir.File("rig.txtpb"), scenario.inputs.rig).ok());
  GravityPaths paths;
  paths.imu = dir.File("imu.binpb");
  paths.rig = dir.File("rig.txtpb");
  paths.out = dir.File("gravity.txtpb");
  for (const Eigen::Vector3d& normal : std::vector<Eigen::Vector3d>{
           Eigen::Vector3d(std::nan(""), 0, 1), Eigen::Vector3d::Zero()}) {
    std::vector<proto::GroundPlane> planes = scenario.inputs.ground;
    *planes[5].mutable_normal_in_lidar() = ToProto(normal);
    RecordWriter ground_writer;
    ASSERT_TRUE(
        ground_writer.Open(dir.File("ground.binpb"), "tiltcal.proto.GroundPlane", {}, false).ok());
    for (const auto& plane : planes) ASSERT_TRUE(ground_writer.Write(plane).ok());
    ASSERT_TRUE(ground_writer.Close().ok());
    paths.ground = dir.File("ground.binpb");
    const Status status = gravity::Run(paths, DefaultParams(), nullptr);
    ASSERT_FALSE(status.ok()) << normal.transpose();
    EXPECT_NE(status.message().find(paths.ground + ": record 5: normal_in_lidar"),
              std::string::npos)
        << status.message();
    EXPECT_FALSE(testing::FileExists(paths.out));
  }
  paths.ground.clear();
  proto::CalibrationResult no_gravity;
  *no_gravity.mutable_imu_from_lidar() = scenario.inputs.rig.imu_from_lidar();
  ASSERT_TRUE(WriteTextProto(dir.File("calibration.txtpb"), no_gravity).ok());
  paths.calibration = dir.File("calibration.txtpb");
  const Status status = gravity::Run(paths, DefaultParams(), nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(paths.calibration + ": gravity_in_world has norm 0"),
            std::string::npos)
      << status.message();
  EXPECT_FALSE(testing::FileExists(paths.out));
}

}  // namespace
}  // namespace tiltcal::gravity
