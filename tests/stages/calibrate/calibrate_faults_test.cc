// Faults of real recordings that the calibrator's initialisation refuses,
// on the short simulated sequence (short_sequence_fixture.h) changed in
// memory: a gyro in deg/s labelled rad/s, a rig rotation wrong in yaw by
// 90 deg, an IMU upside down that the rig does not declare; and one
// accelerometer sample of 1e300 m/s^2 in the IMU file. Each ends with an
// error saying what the data show, never a result.

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "stages/calibrate/init/rotation_from_motion.h"
#include "tests/stages/calibrate/short_sequence_fixture.h"
#include "tests/stages/calibrate/simulated_calibration.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::calibrate {
namespace {

using CalibrateFaultsTest = ShortSequenceTest;

TEST_F(CalibrateFaultsTest, GyroInDegreesPerSecondIsAnErrorNamingTheRatioAndTheRigField) {
  for (imu::ImuReading& r : inputs_.imu) r.angular_velocity_radps *= geometry::kDegPerRad;
  proto::CalibrationResult result;
  std::string log;
  const Status status = Run(&result, &log);
  ASSERT_FALSE(status.ok()) << log;
  std::printf("%s\n", status.message().c_str());
  EXPECT_NE(status.message().find("deg/s"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("imu_gyro_unit: DEGPS"), std::string::npos) << status.message();
  // The ratio, printed with one decimal, is within 10 % of 57.3.
  EXPECT_NE(status.message().find("times faster than the LiDAR"), std::string::npos)
      << status.message();
  const double ratio = std::stod(status.message().substr(status.message().find("turns ") + 6));
  EXPECT_NEAR(ratio, geometry::kDegPerRad, 0.1 * geometry::kDegPerRad) << status.message();
}

TEST_F(CalibrateFaultsTest, RigYawOffBy90DegreesIsRefusedWithTheAngle) {
  RotateRig(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())));
  proto::CalibrationResult result;
  std::string log;
  const Status status = Run(&result, &log);
  ASSERT_FALSE(status.ok()) << log;
  std::printf("%s\n", status.message().c_str());
  const std::string& m = status.message();
  EXPECT_NE(m.find("about the motion's rotation axis"), std::string::npos) << m;
  EXPECT_NE(m.find("fix it in the rig"), std::string::npos) << m;
  // The angle the data show: 90 deg, either sign (the axis may point down).
  const double angle = std::stod(m.substr(m.find("turned by ") + 10));
  EXPECT_NEAR(std::abs(angle), 90.0, 15.0) << m;
}

TEST_F(CalibrateFaultsTest, UndeclaredUpsideDownImuIsRefusedWithTheAxisAngle) {
  RotateRig(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())));
  proto::CalibrationResult result;
  std::string log;
  const Status status = Run(&result, &log);
  ASSERT_FALSE(status.ok()) << log;
  std::printf("%s\n", status.message().c_str());
  const std::string& m = status.message();
  EXPECT_NE(m.find("rotation axis"), std::string::npos) << m;
  EXPECT_NE(m.find("fix imu_from_lidar.rotation in the rig"), std::string::npos) << m;
  const double angle = std::stod(m.substr(m.find("axis ") + 5));
  EXPECT_GT(angle, 170.0) << m;
}

// The starting extrinsic from the motion (rotation_from_motion.h): the rig
// cases that calibrate alone refuses above, and no guess at all, end within
// 6 deg of the truth, inside what the calibration's initialisation corrects
// (init.max_axis_alignment_deg 10, max_rig_rotation_error_deg 20); the
// calibration started there is within 0.1 deg. On this 16 s sequence with
// the lever arm unknown (zero) every start ends 4.9 deg off (2.8 deg with the
// true lever arm: the centripetal accelerations of the lever arm turn the
// acceleration check); on 40 s sequences within 0.5 deg.
double RotationFromTruthDeg(const Eigen::Quaterniond& q, const proto::SimulationTruth& truth) {
  const Eigen::Quaterniond t = ToEigen(truth.imu_from_lidar()).rotation;
  return geometry::RadToDeg(Eigen::AngleAxisd(q * t.conjugate()).angle());
}

TEST_F(CalibrateFaultsTest, WrongRigRotationsAndNoGuessAreCorrectedFromTheMotion) {
  const Eigen::Quaterniond truth = ToEigen(truth_.imu_from_lidar()).rotation;
  const struct {
    const char* name;
    std::optional<Eigen::Quaterniond> guess;
  } cases[] = {
      {"yaw off by 90 deg",
       Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())) * truth},
      {"upside down (180 deg about x)",
       Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX())) * truth},
      {"identity", Eigen::Quaterniond::Identity()},
      {"no guess", std::nullopt},
  };
  for (const auto& c : cases) {
    RotationFromMotion found;
    const Status status = FindImuFromLidarRotation(inputs_.imu, inputs_.scans, c.guess,
                                                   Eigen::Vector3d::Zero(), LidarImuParams(),
                                                   &found);
    ASSERT_TRUE(status.ok()) << c.name << ": " << status.message();
    const double error_deg = RotationFromTruthDeg(found.imu_from_lidar, truth_);
    std::printf("%s: %.3f deg from the truth after %zu rounds, %.2f s\n", c.name, error_deg,
                found.rounds.size(), found.seconds);
    EXPECT_LT(error_deg, 6.0) << c.name;
    EXPECT_TRUE(found.about_axis_decided) << c.name;
  }
  // The calibration from the start found without a guess.
  RotationFromMotion found;
  ASSERT_TRUE(FindImuFromLidarRotation(inputs_.imu, inputs_.scans, std::nullopt,
                                       Eigen::Vector3d::Zero(), LidarImuParams(), &found)
                  .ok());
  RotateRig(found.imu_from_lidar * ToEigen(inputs_.rig.imu_from_lidar()).rotation.conjugate());
  proto::CalibrationResult result;
  std::string log;
  ASSERT_TRUE(Run(&result, &log).ok()) << log;
  EXPECT_LT(RotationFromTruthDeg(ToEigen(result.imu_from_lidar()).rotation, truth_), 0.1) << log;
}

// A 5 s recording (3 s still, then 2 s of driving off nearly straight) with
// the rig's right rotation, through the executables: exit 1 and an error
// that names the missing turning with the measured amounts, not the rig
// (before, such a sequence's axis disagreement, noise, was blamed on the
// rig, or the noise axis turned a right rig by degrees).
TEST_F(CalibrateFaultsTest, ShortRecordingWithARightRigIsRefusedForItsMotion) {
  proto::SimulateParams scenario;
  ASSERT_TRUE(ReadTextProto(testing::SourceDir() + "/stages/simulate/scenarios/flat_vlp16_40s.txtpb",
                            &scenario)
                  .ok());
  scenario.set_duration_s(5.0);
  SimulatedInputs sim;
  ASSERT_NO_FATAL_FAILURE(SimulateAndDecode(scenario, *dir_, "short_5s", &sim));
  const std::string rig = sim.rig, imu = sim.imu, scans = sim.scans;
  std::string output;
  const std::string params = dir_->File("short_5s_params.txtpb");
  ASSERT_TRUE(WriteTextProto(params, LidarImuParams()).ok());
  const std::string out = dir_->File("short_5s_calibration.txtpb");
  output.clear();
  const int exit_code = testing::RunCommand(
      testing::ToolPath("tiltcal_calibrate") + " --quiet --imu=" + imu + " --scans=" + scans +
          " --rig=" + rig + " --params=" + params + " --out=" + out,
      &output);
  std::printf("%s", output.c_str());
  EXPECT_EQ(exit_code, 1) << output;
  EXPECT_NE(output.find("the motion cannot decide the extrinsic rotation: too little turning"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("init.min_axis_rotation_rad"), std::string::npos) << output;
  EXPECT_NE(output.find("record 30 s or more of driving with turns both ways"), std::string::npos)
      << output;
  EXPECT_EQ(output.find("rig"), std::string::npos) << "the error blames the rig: " << output;
  EXPECT_FALSE(testing::FileExists(out));
  // The pipeline meets the motion first in tiltcal_initial_extrinsic: the
  // same refusal, naming the motion, not the rig.
  const std::string sequence_rig = dir_->File("short_5s_sequence_rig.txtpb");
  output.clear();
  const int search_exit = testing::RunCommand(
      testing::ToolPath("tiltcal_initial_extrinsic") + " --quiet --imu=" + imu + " --scans=" +
          scans + " --rig=" + rig + " --params=" + params + " --out=" + sequence_rig,
      &output);
  std::printf("%s", output.c_str());
  EXPECT_EQ(search_exit, 1) << output;
  EXPECT_NE(output.find("too little turning"), std::string::npos) << output;
  EXPECT_NE(output.find("record 30 s or more of driving with turns both ways"), std::string::npos)
      << output;
  EXPECT_EQ(output.find("rig"), std::string::npos) << "the error blames the rig: " << output;
  EXPECT_FALSE(testing::FileExists(sequence_rig));
}

// Through the executable: exit code 1, one error line, no output left.
TEST_F(CalibrateFaultsTest, WrongRigRotationExitsWithOneAndLeavesNoOutput) {
  proto::Rig rig = inputs_.rig;
  Rigid3d extrinsic = ToEigen(rig.imu_from_lidar());
  extrinsic.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())) *
      extrinsic.rotation;
  *rig.mutable_imu_from_lidar() = ToProto(extrinsic);
  const std::string rig_path = dir_->File("rig_yaw90.txtpb");
  ASSERT_TRUE(WriteTextProto(rig_path, rig).ok());
  const std::string out = dir_->File("calibration_yaw90.txtpb");
  const std::string params = dir_->File("lidar_imu.txtpb");
  ASSERT_TRUE(WriteTextProto(params, LidarImuParams()).ok());
  std::string output;
  const int exit_code = testing::RunCommand(
      testing::ToolPath("tiltcal_calibrate") + " --imu=" + dir_->File("imu.binpb") +
          " --scans=" + dir_->File("scans.binpb.lz4") + " --rig=" + rig_path + " --params=" +
          params + " --out=" + out,
      &output);
  EXPECT_EQ(exit_code, 1) << output;
  EXPECT_NE(output.find("fix it in the rig"), std::string::npos) << output;
  EXPECT_FALSE(testing::FileExists(out));
}

// One accelerometer sample of 1e300 m/s^2: finite, so the IMU reader keeps
// it; its squared residual overflows a double, so no solve can use it. The
// executable must exit 1 with one error line and write no result, whichever
// step meets the value first (initialisation, or the solve's check in
// solve_check.h, tested on its own in solve_check_test.cc).
TEST_F(CalibrateFaultsTest, AccelerometerSampleOf1e300ExitsWithOneLineAndNoResult) {
  std::vector<proto::ImuSample> samples;
  proto::StreamHeader header;
  ASSERT_TRUE(ReadAllRecords<proto::ImuSample>(dir_->File("imu.binpb"), &samples, &header).ok());
  ASSERT_GT(samples.size(), 100u);
  samples[samples.size() / 2].mutable_linear_acceleration_mps2()->set_z(1e300);
  const std::string imu = dir_->File("imu_1e300.binpb");
  RecordWriter writer;
  ASSERT_TRUE(writer.Open(imu, header.payload_type(), header.provenance(), false).ok());
  for (const proto::ImuSample& sample : samples) ASSERT_TRUE(writer.Write(sample).ok());
  ASSERT_TRUE(writer.Close().ok());
  const std::string params = dir_->File("lidar_imu_1e300.txtpb");
  ASSERT_TRUE(WriteTextProto(params, LidarImuParams()).ok());
  const std::string out = dir_->File("calibration_1e300.txtpb");
  std::string output;
  const int exit_code = testing::RunCommand(
      testing::ToolPath("tiltcal_calibrate") + " --quiet --imu=" + imu + " --scans=" +
          dir_->File("scans.binpb.lz4") + " --rig=" + dir_->File("rig.txtpb") +
          " --params=" + params + " --out=" + out,
      &output);
  std::printf("%s", output.c_str());
  EXPECT_EQ(exit_code, 1) << output;
  EXPECT_EQ(output.rfind("tiltcal_calibrate: ", 0), 0u) << output;
  ASSERT_FALSE(output.empty());
  EXPECT_EQ(output.find('\n'), output.size() - 1) << "more than one line:\n" << output;
  EXPECT_FALSE(testing::FileExists(out));
}

}  // namespace
}  // namespace tiltcal::calibrate
