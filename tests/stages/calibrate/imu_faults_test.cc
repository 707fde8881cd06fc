// The IMUs users have, through the executables on the short simulated
// sequence (tests/stages/calibrate/short_flat_vlp16.txtpb, 16 s, LiDAR + IMU
// only): a consumer-grade IMU's scale and axis errors (imu_intrinsics.h) and
// engine vibration felt by the IMU (imu_vibration.h). With the defaults
// (AUTO) each is found, handled and the result is right; with the handling
// OFF the result is SUSPECT (exit 3) naming what the residuals show, never
// OK and wrong. A LiDAR clock drifting against the IMU's, which decode
// measures and the calibration does not model, makes the result WEAK. (40 s sequences with ground residuals, several seeds:
// bench/calibrate/run_imu_faults_bench.sh.)

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "tests/stages/calibrate/short_sequence_fixture.h"
#include "tests/stages/calibrate/simulated_calibration.h"

namespace tiltcal::calibrate {
namespace {

using ImuFaultsTest = ShortSequenceTest;

proto::SimulateParams ShortSequenceWith(const std::string& faults) {
  proto::SimulateParams scenario;
  EXPECT_TRUE(ReadTextProto(testing::SourceDir() + "/tests/stages/calibrate/short_flat_vlp16.txtpb",
                            &scenario)
                  .ok());
  EXPECT_TRUE(ParseTextProto(faults, "faults", scenario.mutable_faults()).ok());
  return scenario;
}

bool AnyContains(const google::protobuf::RepeatedPtrField<std::string>& lines,
                 const std::string& part) {
  for (const std::string& line : lines) {
    if (line.find(part) != std::string::npos) return true;
  }
  return false;
}

void Print(const std::string& name, const CalibrationRun& run) {
  std::printf("%s: exit %d, %s, %.3f deg (sigma %.3f), (%.1f, %.1f, %.1f) mm, tau %.3f ms\n",
              name.c_str(), run.exit_code,
              proto::CalibrationResult::Verdict_Name(run.result.verdict()).c_str(),
              run.rotation_deg, run.max_rotation_sigma_deg, run.translation_m.x() * 1e3,
              run.translation_m.y() * 1e3, run.translation_m.z() * 1e3, run.tau_ms);
}

// 16 s of LiDAR and IMU only: the errors within three of the reported
// sigmas, the in-plane lever arm within 1 cm, tau within 0.5 ms.
void ExpectRightWithinSigmas(const CalibrationRun& run, double max_rotation_deg) {
  EXPECT_LT(run.rotation_deg, 3.0 * run.max_rotation_sigma_deg) << run.output;
  EXPECT_LT(run.rotation_deg, max_rotation_deg) << run.output;
  const Eigen::Vector3d sigma_m = ToEigen(run.result.translation_sigma_m());
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(run.translation_m[i]), 3.0 * sigma_m[i]) << i << ": " << run.output;
  }
  EXPECT_LT(run.translation_m.head<2>().cwiseAbs().maxCoeff(), 0.01) << run.output;
  EXPECT_LT(std::abs(run.tau_ms), 0.5) << run.output;
}

// Gyroscope and accelerometer scale errors of 0.3 to 0.5 %, axes 0.2 to
// 0.3 deg off: AUTO's score test finds them and they are estimated.
TEST_F(ImuFaultsTest, ConsumerImuIsEstimatedWithAutoAndSuspectWithOff) {
  SimulatedInputs sim;
  ASSERT_NO_FATAL_FAILURE(SimulateAndDecode(ShortSequenceWith(R"pb(
                                              gyro_intrinsics {
                                                scale_ppm { x: 4000 y: -3000 z: 5000 }
                                                misalignment_deg { x: 0.3 y: -0.2 z: 0.25 }
                                              }
                                              accel_intrinsics {
                                                scale_ppm { x: -5000 y: 4000 z: 3000 }
                                                misalignment_deg { x: -0.3 y: 0.2 z: -0.2 }
                                              })pb"),
                                            *dir_, "consumer", &sim));
  for (const auto mode : {proto::ImuIntrinsicsParams::AUTO, proto::ImuIntrinsicsParams::OFF}) {
    const std::string name = "consumer_" + proto::ImuIntrinsicsParams::Mode_Name(mode);
    proto::CalibrateParams params = LidarImuParams();
    params.mutable_imu_intrinsics()->set_mode(mode);
    const CalibrationRun run = RunCalibrate(sim, params, *dir_, name);
    ASSERT_TRUE(run.has_result) << name << ": " << run.output;
    Print(name, run);
    const proto::ImuIntrinsicsReport& k = run.result.imu_intrinsics();
    std::printf("  score %.0f, gyro z scale %.0f ppm (truth %.0f)\n", k.score_chi2(),
                k.gyro().scale_ppm().z(), sim.truth.gyro_intrinsics().scale_ppm().z());
    EXPECT_TRUE(k.found()) << name << ": " << run.output;
    if (mode == proto::ImuIntrinsicsParams::AUTO) {
      EXPECT_EQ(run.exit_code, 0) << run.output;
      EXPECT_NE(run.result.verdict(), proto::CalibrationResult::SUSPECT) << run.output;
      EXPECT_TRUE(k.estimated());
      ExpectRightWithinSigmas(run, 0.25);
      EXPECT_NEAR(k.gyro().scale_ppm().z(), 5000.0, 3.0 * k.gyro().scale_sigma_ppm().z() + 100.0);
      EXPECT_GT(k.gyro().scale_sigma_ppm().z(), 0.0);
    } else {
      EXPECT_EQ(run.exit_code, 3) << run.output;
      EXPECT_EQ(run.result.verdict(), proto::CalibrationResult::SUSPECT);
      EXPECT_FALSE(k.estimated());
      EXPECT_TRUE(AnyContains(run.result.verdict_reasons(),
                              "the IMU's scale and axis errors show in the residuals"))
          << run.output;
    }
  }
}

// An idling engine: 37 Hz, 1.5 m/s^2 and 0.05 rad/s per axis, also during
// the static start (53 and 12 times imu_noise's sigmas). AUTO low-passes
// and thins the readings (every 4th at 200 Hz: 50 Hz): the static start
// is found and the result is right; OFF leaves it in the residuals: SUSPECT.
TEST_F(ImuFaultsTest, VibrationIsFilteredWithAutoAndSuspectWithOff) {
  SimulatedInputs sim;
  ASSERT_NO_FATAL_FAILURE(SimulateAndDecode(
      ShortSequenceWith("imu_vibration { frequency_hz: 37 accel_amplitude_mps2: 1.5 "
                        "gyro_amplitude_radps: 0.05 when: ALWAYS }"),
      *dir_, "vibration", &sim));
  for (const auto mode : {proto::ImuVibrationParams::AUTO, proto::ImuVibrationParams::OFF}) {
    const std::string name = "vibration_" + proto::ImuVibrationParams::Mode_Name(mode);
    proto::CalibrateParams params = LidarImuParams();
    params.mutable_imu_vibration()->set_mode(mode);
    const CalibrationRun run = RunCalibrate(sim, params, *dir_, name);
    ASSERT_TRUE(run.has_result) << name << ": " << run.output;
    Print(name, run);
    const proto::ImuVibrationReport& v = run.result.imu_vibration();
    EXPECT_TRUE(v.found()) << run.output;
    EXPECT_NEAR(v.accel_peak_hz(), 37.0, 0.5);
    EXPECT_NEAR(v.accel_rms_mps2().x(), 1.5 / std::sqrt(2.0), 0.05);
    EXPECT_TRUE(AnyContains(run.result.verdict_notes(), "IMU vibration above the spline's band"))
        << run.output;
    if (mode == proto::ImuVibrationParams::AUTO) {
      EXPECT_EQ(run.exit_code, 0) << run.output;
      EXPECT_NE(run.result.verdict(), proto::CalibrationResult::SUSPECT) << run.output;
      EXPECT_TRUE(v.filtered());
      EXPECT_EQ(v.decimation(), 4);
      EXPECT_NEAR(v.accel_sigma_mps2(), params.imu_noise().accel_sigma_mps2() / 2.0,
                  1e-12);
      EXPECT_TRUE(run.result.static_start()) << run.output;
      ExpectRightWithinSigmas(run, 0.15);
    } else {
      EXPECT_EQ(run.exit_code, 3) << run.output;
      EXPECT_FALSE(v.filtered());
      EXPECT_TRUE(AnyContains(run.result.verdict_reasons(), "accel residuals far above their noise model"))
          << run.output;
    }
  }
}

// A LiDAR clock 100 ppm fast: τ moves by 1.6 ms over the 16 s. Decode says
// so (imu.binpb's provenance); the calibration fits one τ, so its result is
// WEAK with decode's finding, never OK.
TEST_F(ImuFaultsTest, ClockDriftMakesTheResultWeakNamingIt) {
  SimulatedInputs sim;
  ASSERT_NO_FATAL_FAILURE(
      SimulateAndDecode(ShortSequenceWith("lidar_clock_drift_ppm: 100"), *dir_, "drift", &sim));
  const CalibrationRun run = RunCalibrate(sim, LidarImuParams(), *dir_, "drift");
  ASSERT_TRUE(run.has_result) << run.output;
  Print("drift", run);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.result.verdict(), proto::CalibrationResult::WEAK) << run.output;
  EXPECT_NE(run.result.clock_drift().find("ppm against the IMU's"), std::string::npos);
  EXPECT_TRUE(AnyContains(run.result.verdict_reasons(),
                          "τ is the offset the whole sequence fits best"))
      << run.output;
  // The fitted τ lies within the drift's span over the sequence.
  EXPECT_LT(std::abs(run.tau_ms), 2.0) << run.output;
}

}  // namespace
}  // namespace tiltcal::calibrate
