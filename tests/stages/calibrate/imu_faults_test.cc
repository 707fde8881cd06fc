// The IMUs users have, through the executables on the short simulated
// sequence (tests/stages/calibrate/short_flat_vlp16.txtpb, 16 s, LiDAR + IMU
// only): a consumer-grade IMU's scale and axis errors (imu_intrinsics.h) and
// engine vibration felt by the IMU (imu_vibration.h). With the defaults
// (AUTO) each is found, handled and the result is right; with the handling
// OFF the result is SUSPECT (exit 3) naming what the residuals show, never
// OK and wrong. A LiDAR clock drifting against the IMU's, which decode
// measures (20 s here): the calibration estimates its rate (time_offset_drift
// AUTO), or, OFF, fits one tau and the result is WEAK. (40 s sequences with
// ground residuals, several seeds, and 160 s with a drift:
// bench/calibrate/run_imu_faults_bench.sh.)

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "tests/stages/calibrate/short_sequence_fixture.h"
#include "tests/stages/calibrate/simulated_calibration.h"

namespace tiltcal::calibrate {
namespace {

// Each test simulates its own sequence into the test's folder.
class ImuFaultsTest : public ::testing::Test {
 protected:
  const std::unique_ptr<testing::TempDir> dir_ = std::make_unique<testing::TempDir>();
};

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

// The true tau at a truth scan: its IMU-clock time minus its LiDAR stamp.
double TrueTimeOffsetS(const proto::TruthScan& scan) {
  return static_cast<double>(scan.true_stamp_ns() - scan.stamp_ns()) * 1e-9;
}

// A LiDAR clock 300 ppm fast on the short sequence made 20 s long: tau falls
// by 6 ms. Decode says so (imu.binpb's provenance). With time_offset_drift AUTO the calibration
// estimates the rate: exit 0, not WEAK on the clocks' account, the rate
// within 3 sigma of the truth and tau at the first and the last scan within
// 0.5 ms of the truth. With OFF it fits one tau, and the result is WEAK with
// decode's finding, never OK.
TEST_F(ImuFaultsTest, ClockDriftIsEstimatedOrMakesTheResultWeak) {
  constexpr double kRatePpm = 300.0;
  proto::SimulateParams scenario =
      ShortSequenceWith("lidar_clock_drift_ppm: " + std::to_string(kRatePpm));
  scenario.set_duration_s(20.0);
  SimulatedInputs sim;
  ASSERT_NO_FATAL_FAILURE(SimulateAndDecode(scenario, *dir_, "drift", &sim));
  ASSERT_GE(sim.truth.scans_size(), 2);
  const proto::TruthScan& first = sim.truth.scans(0);
  const proto::TruthScan& last = sim.truth.scans(sim.truth.scans_size() - 1);

  const CalibrationRun run = RunCalibrate(sim, LidarImuParams(), *dir_, "drift_auto");
  ASSERT_TRUE(run.has_result) << run.output;
  Print("drift AUTO", run);
  const proto::TimeOffsetDriftReport& d = run.result.time_offset_drift();
  std::printf("  rate %+.1f +- %.1f ppm (truth %+.1f); tau %.3f / %.3f ms at the ends (truth "
              "%.3f / %.3f)\n",
              d.rate_ppm(), d.rate_sigma_ppm(), kRatePpm, d.time_offset_start_s() * 1e3,
              d.time_offset_end_s() * 1e3, TrueTimeOffsetS(first) * 1e3,
              TrueTimeOffsetS(last) * 1e3);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.result.verdict(), proto::CalibrationResult::SUSPECT) << run.output;
  EXPECT_FALSE(run.result.clock_drift().empty()) << run.output;
  EXPECT_FALSE(AnyContains(run.result.verdict_reasons(), "τ is the offset the whole sequence"))
      << run.output;
  EXPECT_FALSE(AnyContains(run.result.verdict_reasons(), "clock")) << run.output;
  EXPECT_TRUE(AnyContains(run.result.verdict_notes(), "clock drift estimated")) << run.output;
  EXPECT_NE(run.output.find("clock drift estimated"), std::string::npos) << run.output;
  ASSERT_TRUE(d.estimated()) << run.output;
  EXPECT_FALSE(d.weak()) << run.output;
  EXPECT_GT(d.rate_sigma_ppm(), 0.0);
  EXPECT_LT(std::abs(d.rate_ppm() - kRatePpm), 3.0 * d.rate_sigma_ppm()) << run.output;
  // The report's ends are the truth's first and last scans.
  const double first_s = static_cast<double>(first.stamp_ns() - sim.truth.start_stamp_ns()) * 1e-9;
  const double last_s = static_cast<double>(last.stamp_ns() - sim.truth.start_stamp_ns()) * 1e-9;
  EXPECT_NEAR(d.start_time_s(), first_s, 1e-3);
  EXPECT_NEAR(d.end_time_s(), last_s, 1e-3);
  EXPECT_NEAR(d.time_offset_start_s(), TrueTimeOffsetS(first), 0.5e-3) << run.output;
  EXPECT_NEAR(d.time_offset_end_s(), TrueTimeOffsetS(last), 0.5e-3) << run.output;
  EXPECT_GT(d.time_offset_start_sigma_s(), 0.0);

  const CalibrationRun off = RunCalibrate(
      sim, testing::DefaultCalibrateParamsWith(R"pb(
        ground {
          flat { mode: OFF }
          dist { mode: OFF }
          incl { mode: OFF }
          up { mode: OFF }
        }
        time_offset_drift { mode: OFF })pb"),
      *dir_, "drift_off");
  ASSERT_TRUE(off.has_result) << off.output;
  Print("drift OFF", off);
  EXPECT_EQ(off.exit_code, 0) << off.output;
  EXPECT_EQ(off.result.verdict(), proto::CalibrationResult::WEAK) << off.output;
  EXPECT_FALSE(off.result.time_offset_drift().estimated());
  EXPECT_TRUE(AnyContains(off.result.verdict_reasons(),
                          "τ is the offset the whole sequence fits best"))
      << off.output;
  // The single tau lies between the truth's ends.
  EXPECT_LT(off.result.time_offset_s(), TrueTimeOffsetS(first));
  EXPECT_GT(off.result.time_offset_s(), TrueTimeOffsetS(last));
}

}  // namespace
}  // namespace tiltcal::calibrate
