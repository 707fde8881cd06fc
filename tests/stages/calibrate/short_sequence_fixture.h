#ifndef TILTCAL_TESTS_STAGES_CALIBRATE_SHORT_SEQUENCE_FIXTURE_H_
#define TILTCAL_TESTS_STAGES_CALIBRATE_SHORT_SEQUENCE_FIXTURE_H_

// The short simulated flat sequence (tests/stages/calibrate/
// short_flat_vlp16.txtpb), simulated and decoded once per test suite, read
// into CalibrateInputs for each test, to be changed in memory (a clock
// offset, a gyro unit, a rig rotation) and calibrated LiDAR + IMU only.

#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/calibrate/calibrate.h"
#include "tests/stages/calibrate/calibrate_params_text.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::calibrate {

// LiDAR + IMU only.
inline proto::CalibrateParams LidarImuParams() {
  return testing::DefaultCalibrateParamsWith(R"pb(
    ground {
      flat { mode: OFF }
      dist { mode: OFF }
      incl { mode: OFF }
      up { mode: OFF }
    })pb");
}

// The sequence, simulated and decoded once for all tests of the suite.
class ShortSequenceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<testing::TempDir>();
    const std::string src = testing::SourceDir();
    for (const char* tool : {"tiltcal_simulate", "tiltcal_decode", "tiltcal_calibrate"}) {
      if (!testing::FileExists(testing::ToolPath(tool))) {
        setup_error_ = std::string("build ") + tool + " first";
        return;
      }
    }
    const std::string commands[] = {
        testing::ToolPath("tiltcal_simulate") + " --quiet --params=" + src +
            "/tests/stages/calibrate/short_flat_vlp16.txtpb --out_bag=" + dir_->File("s.bag") +
            " --out_truth=" + dir_->File("truth.txtpb") + " --out_rig=" + dir_->File("rig.txtpb"),
        testing::ToolPath("tiltcal_decode") + " --bag=" + dir_->File("s.bag") +
            " --rig=" + dir_->File("rig.txtpb") + " --out_imu=" + dir_->File("imu.binpb") +
            " --out_scans=" + dir_->File("scans.binpb.lz4")};
    for (const std::string& command : commands) {
      std::string out;
      if (testing::RunCommand(command, &out) != 0) {
        setup_error_ = command + "\n" + out;
        return;
      }
    }
    if (!ReadTextProto(dir_->File("truth.txtpb"), &truth_).ok()) {
      setup_error_ = "no truth";
    }
  }
  static void TearDownTestSuite() { dir_.reset(); }

  void SetUp() override {
    ASSERT_TRUE(setup_error_.empty()) << setup_error_;
    ASSERT_TRUE(ReadCalibrateInputs(Paths(), LidarImuParams(), &inputs_).ok());
  }

  static CalibratePaths Paths() {
    CalibratePaths paths;
    paths.imu = dir_->File("imu.binpb");
    paths.scans = dir_->File("scans.binpb.lz4");
    paths.rig = dir_->File("rig.txtpb");
    paths.out = dir_->File("calibration.txtpb");
    return paths;
  }

  // The rig's C_bl turned by `error` on the IMU side: C_meas = error C_bl.
  void RotateRig(const Eigen::Quaterniond& error) {
    Rigid3d rig = ToEigen(inputs_.rig.imu_from_lidar());
    rig.rotation = (error * rig.rotation).normalized();
    *inputs_.rig.mutable_imu_from_lidar() = ToProto(rig);
  }

  // Calibrate on the inputs; the error message when it fails.
  Status Run(proto::CalibrationResult* result, std::string* log_text) {
    std::ostringstream log;
    const Status status = Calibrate(inputs_, LidarImuParams(), result, nullptr, &log);
    *log_text = log.str();
    return status;
  }

  static std::unique_ptr<testing::TempDir> dir_;
  static std::string setup_error_;
  static proto::SimulationTruth truth_;
  CalibrateInputs inputs_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_TESTS_STAGES_CALIBRATE_SHORT_SEQUENCE_FIXTURE_H_
