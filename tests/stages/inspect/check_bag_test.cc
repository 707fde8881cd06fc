// `tiltcal_inspect check` on whole bags: a short simulated sequence
// (tiltcal_simulate's library), and copies of it rewritten to carry the
// faults of real recordings (IMU in g and deg/s, holes and repeated stamps,
// no static start, no rotation, no LiDAR topic, LiDAR stamps on another
// clock), and a simulation with a vibrating IMU, a drifting LiDAR clock
// and dropped scans. Each asserts the numbers, the statements and the verdict; the
// command-line tests assert the exit codes.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "bag/ros1/bag_reader.h"
#include "bag/ros1/bag_writer.h"
#include "bag/ros1/message_encoding.h"
#include "bag/ros1/messages.h"
#include "common/imu/imu_units.h"
#include "common/io/text_proto.h"
#include "stages/inspect/bag_survey.h"
#include "stages/inspect/check.h"
#include "stages/inspect/check_findings.h"
#include "stages/inspect/default_params_text.h"
#include "stages/simulate/simulate.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/truth.pb.h"

namespace tiltcal::inspect {
namespace {

constexpr int64_t kStartNs = 1700000000000000000LL;
constexpr double kDurationS = 10.0;
constexpr int64_t kImuSamples = 2001;  // 200 Hz, both ends included

// One simulated sequence for every test: the short test scenario, 10 s with
// a 1.5 s static start (the static detection needs 1 s) on a figure eight
// small enough to turn both ways once (6 m by 3 m at 1.5 m/s).
class SimulatedBag {
 public:
  // faults: SimFaultParams in text format ("" = none).
  explicit SimulatedBag(const std::string& faults = "") {
    proto::SimulateParams scenario;
    const Status read = ReadTextProto(
        testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb", &scenario);
    EXPECT_TRUE(read.ok()) << read.message();
    scenario.set_duration_s(kDurationS);
    scenario.set_start_stamp_ns(kStartNs);
    scenario.mutable_trajectory()->set_static_start_s(1.5);
    scenario.mutable_trajectory()->set_length_m(6.0);
    scenario.mutable_trajectory()->set_width_m(3.0);
    scenario.set_num_threads(2);
    const Status parsed = ParseTextProto(faults, "faults", scenario.mutable_faults());
    EXPECT_TRUE(parsed.ok()) << parsed.message();
    simulate::SimulatePaths paths;
    paths.out_bag = dir_.File("run.bag");
    paths.out_truth = dir_.File("truth.txtpb");
    paths.out_rig = dir_.File("rig.txtpb");
    const Status ran = simulate::Run(paths, scenario, nullptr);
    EXPECT_TRUE(ran.ok()) << ran.message();
    EXPECT_TRUE(ReadTextProto(paths.out_truth, &truth_).ok());
  }
  std::string bag() const { return dir_.File("run.bag"); }
  std::string rig() const { return dir_.File("rig.txtpb"); }
  const proto::SimulationTruth& truth() const { return truth_; }

 private:
  testing::TempDir dir_;
  proto::SimulationTruth truth_;
};

// Simulated once per test process; destroyed (its folder removed) at exit.
const SimulatedBag& Simulated() {
  static const SimulatedBag bag;
  return bag;
}

// How a copy of the simulated bag differs from it.
struct BagEdits {
  // IMU message `index` (0-based, in record order): false drops it; may
  // change its values or stamp.
  std::function<bool(size_t index, ros1::ImuMessage* imu)> imu;
  size_t repeat_imu_index = SIZE_MAX;  // written twice
  bool drop_lidar = false;
  int64_t lidar_stamp_shift_ns = 0;  // header stamps only; record times kept
};

void RewriteBag(const std::string& in, const std::string& out, const BagEdits& edits) {
  ros1::BagReader reader;
  ASSERT_TRUE(reader.Open(in).ok());
  ros1::BagWriter writer;
  ASSERT_TRUE(writer.Open(out, ros1::ChunkCompression::kNone, 1 << 18).ok());
  std::map<std::string, uint32_t> connection_of_topic;
  ros1::ImuMessage imu;
  size_t imu_index = 0;
  const Status read = reader.ReadMessages({}, [&](const ros1::MessageView& m) {
    const ros1::Connection& c = *m.connection;
    const bool is_imu = c.type == ros1::kImuType;
    if (!is_imu && edits.drop_lidar) return Status::Ok();
    if (!connection_of_topic.count(c.topic)) {
      connection_of_topic[c.topic] =
          writer.AddConnection(c.topic, c.type, c.md5sum, c.message_definition);
    }
    const uint32_t connection = connection_of_topic[c.topic];
    std::string message(reinterpret_cast<const char*>(m.data), m.size);
    if (is_imu) {
      TILTCAL_RETURN_IF_ERROR(ros1::DecodeImu(m.data, m.size, &imu));
      const size_t index = imu_index++;
      if (edits.imu && !edits.imu(index, &imu)) return Status::Ok();
      message.clear();
      ros1::SerializeImu(imu.header.seq, ros1::RosTimeToNs(imu.header.stamp), imu.header.frame_id,
                         Eigen::Vector3d(imu.angular_velocity[0], imu.angular_velocity[1],
                                         imu.angular_velocity[2]),
                         Eigen::Vector3d(imu.linear_acceleration[0], imu.linear_acceleration[1],
                                         imu.linear_acceleration[2]),
                         1e-6, 1e-4, &message);
      if (index == edits.repeat_imu_index) {
        TILTCAL_RETURN_IF_ERROR(writer.Write(connection, m.time_ns, message));
      }
    } else if (edits.lidar_stamp_shift_ns != 0) {
      // std_msgs/Header: seq u32, then stamp u32 sec + u32 nsec at byte 4.
      ros1::RosTime stamp;
      std::memcpy(&stamp.sec, message.data() + 4, 4);
      std::memcpy(&stamp.nsec, message.data() + 8, 4);
      EXPECT_TRUE(ros1::NsToRosTime(ros1::RosTimeToNs(stamp) + edits.lidar_stamp_shift_ns, &stamp));
      std::memcpy(message.data() + 4, &stamp.sec, 4);
      std::memcpy(message.data() + 8, &stamp.nsec, 4);
    }
    return writer.Write(connection, m.time_ns, message);
  });
  ASSERT_TRUE(read.ok()) << read.message();
  ASSERT_TRUE(writer.Close().ok());
}

proto::CheckParams Defaults() {
  return testing::DefaultParamsWith<proto::CheckParams>(DefaultParamsText());
}

struct CheckRun {
  Status status;
  std::string report;
  CheckFindings findings;
};

CheckRun Check(const std::string& bag, const std::string& rig) {
  CheckRun run;
  std::ostringstream out;
  run.status = RunCheck({bag, rig}, Defaults(), out);
  run.report = out.str();
  proto::Rig rig_proto;
  if (!rig.empty()) {
    EXPECT_TRUE(ReadTextProto(rig, &rig_proto).ok());
  }
  BagSurvey survey;
  BagSurveyOptions options;
  options.imu_topic = rig_proto.imu_topic();
  options.lidar_topic = rig_proto.lidar_topic();
  EXPECT_TRUE(SurveyBag(bag, options, &survey).ok());
  run.findings = AnalyseSurvey(survey, rig.empty() ? nullptr : &rig_proto, Defaults());
  return run;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

bool AnyContains(const std::vector<std::string>& lines, const std::string& part) {
  for (const std::string& line : lines) {
    if (Contains(line, part)) return true;
  }
  return false;
}

TEST(CheckBag, CleanSimulatedSequence) {
  const SimulatedBag& sim = Simulated();
  const CheckRun run = Check(sim.bag(), sim.rig());
  ASSERT_TRUE(run.status.ok()) << run.status.message() << "\n" << run.report;
  const CheckFindings& f = run.findings;
  EXPECT_EQ(f.imu_topic, "/imu/data");
  EXPECT_EQ(f.lidar_topic, "/velodyne_points");
  // IMU: 200 Hz over 10 s, both ends included, no jitter, nothing missing.
  EXPECT_EQ(f.imu.stamps.count, kImuSamples);
  EXPECT_NEAR(f.imu.stamps.rate_hz, 200.0, 1e-6);
  EXPECT_LT(f.imu.stamps.interval_stddev_s, 1e-6);
  EXPECT_EQ(f.imu.stamps.num_gaps + f.imu.stamps.num_duplicates + f.imu.stamps.num_backwards, 0);
  EXPECT_EQ(f.imu.accel.unit, imu::AccelUnit::kMetresPerSecond2);
  EXPECT_TRUE(f.imu.accel.from_static_samples);
  EXPECT_NEAR(f.imu.accel.median_norm, 9.81, 0.15);
  EXPECT_EQ(f.imu.gyro_unit, imu::GyroUnit::kRadiansPerSecond);
  ASSERT_TRUE(f.imu.static_start.found);
  EXPECT_NEAR(f.imu.static_start.end_s, 1.5, 0.35);
  EXPECT_NEAR(f.imu.static_start.mean_gyro_radps.x(), 0.002, 5e-4);  // the simulated bias
  EXPECT_GE(f.imu.excitation.yaw_rate_sign_changes, 1);  // a figure eight turns both ways
  // LiDAR: 10 Hz, one scan per truth scan, Velodyne stamps at the sweep end.
  EXPECT_EQ(f.lidar.stamps.count, sim.truth().scans_size());
  EXPECT_NEAR(f.lidar.stamps.rate_hz, 10.0, 1e-6);
  EXPECT_GT(f.lidar.median_points, 5000);
  EXPECT_EQ(f.lidar.layout.time_field, "time");
  EXPECT_EQ(f.lidar.layout.time_type, "FLOAT32");
  EXPECT_EQ(f.lidar.layout.ring_field, "ring");
  EXPECT_NEAR(f.lidar.min_time_offset_s, -0.1, 0.002);
  EXPECT_NEAR(f.lidar.max_time_offset_s, 0.0, 0.002);
  EXPECT_TRUE(f.lidar.up_from_rig);
  EXPECT_EQ(f.lidar.scans_with_ground, f.lidar.sampled_scans);
  EXPECT_GT(f.lidar.structure_fraction, 0.01);
  // Clock: the IMU spans [start, start + 6 s]; the LiDAR the truth's stamps.
  const int64_t first_scan_ns = sim.truth().scans(0).stamp_ns();
  const int64_t last_scan_ns = sim.truth().scans(sim.truth().scans_size() - 1).stamp_ns();
  EXPECT_EQ(f.imu.stamps.first_ns, kStartNs);
  EXPECT_EQ(f.imu.stamps.last_ns, kStartNs + 10'000'000'000LL);
  EXPECT_EQ(f.lidar.stamps.first_ns, first_scan_ns);
  EXPECT_NEAR(f.clock.overlap_s, 1e-9 * (last_scan_ns - first_scan_ns), 1e-9);
  EXPECT_TRUE(f.problems.empty());
  // No vibration: the high-passed readings are the white noise above 12 Hz
  // (accelerometer 1e-3 m/s^2/sqrt(Hz): 0.013 m/s^2), not the body's sway.
  EXPECT_FALSE(f.imu.gyro_vibrates);
  EXPECT_FALSE(f.imu.accel_vibrates);
  EXPECT_LT(f.imu.vibration.accel.rms.maxCoeff(), 0.02);
  EXPECT_LT(f.imu.vibration.gyro.rms.maxCoeff(), 0.004);
  // The simulator's record times are the stamps: no clock rate to measure.
  EXPECT_FALSE(f.clock.lidar_vs_imu.measured);
  EXPECT_FALSE(AnyContains(f.notes, "vibration"));
  // The report.
  EXPECT_TRUE(Contains(run.report, "  samples                  2001\n")) << run.report;
  EXPECT_TRUE(Contains(run.report, "  rate                     200.00 Hz")) << run.report;
  EXPECT_TRUE(Contains(run.report, "  accelerometer            m/s²")) << run.report;
  EXPECT_TRUE(Contains(run.report, "  static start             yes")) << run.report;
  EXPECT_TRUE(Contains(run.report, "  point time               time FLOAT32")) << run.report;
  EXPECT_TRUE(Contains(run.report, "stamps at the end of the sweep")) << run.report;
  EXPECT_TRUE(Contains(run.report, "  ring                     ring UINT16")) << run.report;
  EXPECT_TRUE(Contains(run.report, "\nverdict: can be calibrated\n")) << run.report;
}

// Engine vibration at 37 Hz (1.5 m/s², 0.05 rad/s per axis, also during the
// static start), a LiDAR clock 100 ppm fast against the IMU's (1 ms of τ
// over the 10 s) and 10 % of the scans dropped: each is measured and said.
TEST(CheckBag, VibrationClockDriftAndDroppedScansAreMeasuredAndSaid) {
  const SimulatedBag sim(
      "imu_vibration { frequency_hz: 37 accel_amplitude_mps2: 1.5 gyro_amplitude_radps: 0.05 } "
      "lidar_clock_drift_ppm: 100 lidar_drop_fraction: 0.1");
  const CheckRun run = Check(sim.bag(), sim.rig());
  ASSERT_TRUE(run.status.ok()) << run.status.message() << "\n" << run.report;
  const CheckFindings& f = run.findings;
  // A sinusoid of amplitude A has RMS A / sqrt(2); the noise adds in quadrature.
  EXPECT_TRUE(f.imu.gyro_vibrates);
  EXPECT_TRUE(f.imu.accel_vibrates);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(f.imu.vibration.accel.rms[axis], 1.5 / std::sqrt(2.0), 0.05);
    EXPECT_NEAR(f.imu.vibration.gyro.rms[axis], 0.05 / std::sqrt(2.0), 0.003);
  }
  EXPECT_NEAR(f.imu.vibration.accel.peak_frequency_hz, 37.0, 0.5);
  EXPECT_NEAR(f.imu.vibration.gyro.peak_frequency_hz, 37.0, 0.5);
  EXPECT_TRUE(AnyContains(f.notes, "IMU vibration above the motion's band")) << run.report;
  // The idling engine hides the static start; the low-pass finds it, as
  // the calibration does.
  EXPECT_TRUE(f.imu.static_start.found) << run.report;
  EXPECT_TRUE(f.imu.static_start_after_low_pass);
  EXPECT_NEAR(f.imu.static_start.end_s, 1.5, 0.35);
  EXPECT_TRUE(Contains(run.report, "(vibration, peak 37.0 Hz)")) << run.report;
  // The drift: LiDAR stamps against the record times (the IMU's clock).
  ASSERT_TRUE(f.clock.lidar_vs_imu.measured);
  EXPECT_NEAR(f.clock.lidar_vs_imu.rate_ppm, 100.0, 2.0);
  EXPECT_LT(f.clock.lidar_vs_imu.sigma_ppm, 2.0);
  EXPECT_NEAR(f.clock.lidar_vs_imu.time_offset_drift_s, 100e-6 * f.clock.overlap_s, 1e-5);
  EXPECT_TRUE(AnyContains(f.notes, "ppm against the IMU's")) << run.report;
  // The dropped scans are gaps: one per missing run of scans.
  const int dropped = static_cast<int>(std::lround(10.0 * kDurationS)) - sim.truth().scans_size();
  ASSERT_GT(dropped, 0);
  EXPECT_GT(f.lidar.stamps.num_gaps, 0);
  EXPECT_NEAR(static_cast<double>(f.lidar.stamps.num_missing), dropped, 1.0);
  EXPECT_TRUE(AnyContains(f.notes, "scan(s) dropped")) << run.report;
}

TEST(CheckBag, ImuInGAndDegreesPerSecondIsDetectedAndWillBeConverted) {
  const SimulatedBag& sim = Simulated();
  testing::TempDir dir;
  BagEdits edits;
  edits.imu = [](size_t, ros1::ImuMessage* m) {
    for (int k = 0; k < 3; ++k) {
      m->angular_velocity[k] /= imu::kRadiansPerDegree;
      m->linear_acceleration[k] /= imu::kStandardGravityMps2;
    }
    return true;
  };
  RewriteBag(sim.bag(), dir.File("units.bag"), edits);
  const CheckRun run = Check(dir.File("units.bag"), sim.rig());
  ASSERT_TRUE(run.status.ok()) << run.status.message();
  EXPECT_EQ(run.findings.imu.accel.unit, imu::AccelUnit::kStandardGravity);
  EXPECT_NEAR(run.findings.imu.accel.median_norm, 1.0, 0.02);
  EXPECT_EQ(run.findings.imu.gyro_unit, imu::GyroUnit::kDegreesPerSecond);
  EXPECT_TRUE(run.findings.imu.static_start.found);  // detected after the conversion
  EXPECT_TRUE(AnyContains(run.findings.notes, "IMU accelerometer in g: it will be converted"));
  EXPECT_TRUE(AnyContains(run.findings.notes, "IMU gyro in deg/s"));
  EXPECT_TRUE(Contains(run.report, "  accelerometer            g (median |f| 0.99")) << run.report;
  EXPECT_TRUE(Contains(run.report, "  gyro                     deg/s")) << run.report;
}

TEST(CheckBag, ImuHoleRepeatedAndBackwardStampsAreCounted) {
  const SimulatedBag& sim = Simulated();
  testing::TempDir dir;
  BagEdits edits;
  // Samples 400..409 dropped: one interval of 11 × 5 ms. Sample 700 written
  // twice. Sample 800 stamped 7.5 ms early (before 799).
  edits.imu = [](size_t index, ros1::ImuMessage* m) {
    if (index >= 400 && index < 410) return false;
    if (index == 800) {
      ros1::NsToRosTime(ros1::RosTimeToNs(m->header.stamp) - 7'500'000, &m->header.stamp);
    }
    return true;
  };
  edits.repeat_imu_index = 700;
  RewriteBag(sim.bag(), dir.File("holes.bag"), edits);
  const CheckRun run = Check(dir.File("holes.bag"), sim.rig());
  ASSERT_TRUE(run.status.ok()) << run.status.message();
  const StampStatistics& s = run.findings.imu.stamps;
  EXPECT_EQ(s.count, kImuSamples - 10 + 1);
  EXPECT_EQ(s.num_gaps, 1);
  EXPECT_NEAR(s.longest_gap_s, 0.055, 1e-9);
  EXPECT_EQ(s.num_duplicates, 1);
  EXPECT_EQ(s.num_backwards, 1);
  EXPECT_GT(s.interval_stddev_s, 1e-4);  // the 12.5 ms interval after the early stamp
  EXPECT_TRUE(AnyContains(run.findings.notes, "1 gap(s) in the IMU stamps (longest 0.055 s)"));
  EXPECT_TRUE(AnyContains(run.findings.notes, "1 repeated IMU stamp(s)"));
  EXPECT_TRUE(AnyContains(run.findings.notes, "1 IMU stamp(s) earlier than the one before"));
  EXPECT_TRUE(Contains(run.report,
                       "  gaps                     1 (> 3 nominal intervals), "
                       "about 10 message(s) missing, longest 0.055 s"))
      << run.report;
}

TEST(CheckBag, NoStaticStartIsSaid) {
  const SimulatedBag& sim = Simulated();
  testing::TempDir dir;
  BagEdits edits;
  edits.imu = [](size_t index, ros1::ImuMessage*) { return index >= 240; };  // from 1.2 s
  RewriteBag(sim.bag(), dir.File("moving.bag"), edits);
  const CheckRun run = Check(dir.File("moving.bag"), sim.rig());
  ASSERT_TRUE(run.status.ok()) << run.status.message();
  EXPECT_FALSE(run.findings.imu.static_start.found);
  EXPECT_TRUE(AnyContains(run.findings.notes, "no static start: the gyro bias starts at zero"));
  EXPECT_TRUE(Contains(run.report, "  static start             no\n")) << run.report;
}

TEST(CheckBag, NoRotationCannotBeCalibrated) {
  const SimulatedBag& sim = Simulated();
  testing::TempDir dir;
  BagEdits edits;
  edits.imu = [](size_t, ros1::ImuMessage* m) {
    m->angular_velocity[0] = 0.002;
    m->angular_velocity[1] = -0.003;
    m->angular_velocity[2] = 0.0015;
    return true;
  };
  RewriteBag(sim.bag(), dir.File("still.bag"), edits);
  const CheckRun run = Check(dir.File("still.bag"), sim.rig());
  ASSERT_FALSE(run.status.ok());
  EXPECT_TRUE(
      Contains(run.status.message(), dir.File("still.bag") + ": cannot be calibrated: no rotation"))
      << run.status.message();
  EXPECT_TRUE(Contains(run.report,
                       "\nverdict: cannot be calibrated\n  - no rotation: 95th "
                       "percentile of |ω| is 0.0000 rad/s"))
      << run.report;
}

TEST(CheckBag, BagWithoutLidarTopicCannotBeCalibrated) {
  const SimulatedBag& sim = Simulated();
  testing::TempDir dir;
  BagEdits edits;
  edits.drop_lidar = true;
  RewriteBag(sim.bag(), dir.File("imu_only.bag"), edits);
  const CheckRun run = Check(dir.File("imu_only.bag"), "");
  ASSERT_FALSE(run.status.ok());
  EXPECT_EQ(run.status.message(),
            dir.File("imu_only.bag") +
                ": cannot be calibrated: LiDAR: no sensor_msgs/PointCloud2 or "
                "livox_ros_driver/CustomMsg or livox_ros_driver2/CustomMsg topic in the bag "
                "(topics: /imu/data)");
  EXPECT_TRUE(Contains(run.report, "LiDAR    (none)\n")) << run.report;
  EXPECT_EQ(run.findings.imu.stamps.count, kImuSamples);  // the IMU part is still reported
}

TEST(CheckBag, LidarStampsOnAnotherClockHaveNoOverlap) {
  const SimulatedBag& sim = Simulated();
  testing::TempDir dir;
  BagEdits edits;
  edits.lidar_stamp_shift_ns = 600'000'000'000LL;  // 10 min
  RewriteBag(sim.bag(), dir.File("clock.bag"), edits);
  const CheckRun run = Check(dir.File("clock.bag"), sim.rig());
  ASSERT_FALSE(run.status.ok());
  const double apart_s =
      600.0 - 1e-9 * (kStartNs + 10'000'000'000LL - sim.truth().scans(0).stamp_ns());
  EXPECT_NEAR(run.findings.clock.overlap_s, -apart_s, 1e-6);
  EXPECT_TRUE(Contains(run.status.message(),
                       "cannot be calibrated: clock: the IMU stamps "
                       "(1700000000.000 .. 1700000010.000 s) and the "
                       "LiDAR stamps (1700000600."))
      << run.status.message();
  EXPECT_TRUE(Contains(run.status.message(), "do not overlap (apart by"));
  EXPECT_TRUE(Contains(run.status.message(), "lidar_stamp_shift_s"));
  EXPECT_TRUE(Contains(run.report, "  overlap                  NONE: the spans are")) << run.report;
}

TEST(CheckBag, LidarStampsFarBehindTheirRecordTimeHintAtALargeTimeOffset) {
  const SimulatedBag& sim = Simulated();
  testing::TempDir dir;
  BagEdits edits;
  edits.lidar_stamp_shift_ns = -8'000'000'000LL;  // τ = 8 s: stamps = true time − τ
  RewriteBag(sim.bag(), dir.File("tau.bag"), edits);
  const CheckRun run = Check(dir.File("tau.bag"), sim.rig());
  ASSERT_TRUE(run.status.ok()) << run.status.message();  // the spans still overlap by 2 s
  EXPECT_NEAR(run.findings.clock.stamp_offset_difference_s, -8.0, 1e-9);
  EXPECT_TRUE(AnyContains(run.findings.notes, "τ may be beyond ±5 s"));
  EXPECT_TRUE(AnyContains(run.findings.notes, "(τ ≈ 8.000 s)"));
}

// The command line: exit codes and the one error line.
class CheckCommandLine : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!testing::FileExists(testing::ToolPath("tiltcal_inspect"))) {
      GTEST_SKIP() << testing::ToolPath("tiltcal_inspect") << " is not built";
    }
  }
  // stdout and stderr into *output; a redirection in `args` applies to the
  // tool alone (e.g. ">/dev/null" keeps only stderr).
  int Run(const std::string& args, std::string* output) {
    output->clear();
    return testing::RunCommand("(" + testing::ToolPath("tiltcal_inspect") + " " + args + ")",
                               output);
  }
};

TEST_F(CheckCommandLine, ExitCodes) {
  const SimulatedBag& sim = Simulated();
  std::string output;
  EXPECT_EQ(Run("check --bag=" + sim.bag() + " --rig=" + sim.rig(), &output), 0) << output;
  EXPECT_TRUE(Contains(output, "verdict: can be calibrated")) << output;
  EXPECT_EQ(Run("check", &output), 2) << output;
  EXPECT_EQ(Run("check " + sim.bag(), &output), 2) << output;
  testing::TempDir dir;
  EXPECT_EQ(Run("check --bag=" + dir.File("missing.bag") + " >/dev/null", &output), 1);
  EXPECT_TRUE(Contains(output, "missing.bag")) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;

  // A params value out of its bounds: one line naming the file and the field.
  {
    std::ofstream params(dir.File("check.txtpb"));
    params << "imu { gap_factor: 0.5 }\n";
  }
  EXPECT_EQ(Run("check --bag=" + sim.bag() + " --params=" + dir.File("check.txtpb") + " >/dev/null",
                &output),
            1);
  EXPECT_TRUE(Contains(output, "check.txtpb")) << output;
  EXPECT_TRUE(Contains(output, "imu.gap_factor")) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;

  BagEdits edits;
  edits.drop_lidar = true;
  RewriteBag(sim.bag(), dir.File("imu_only.bag"), edits);
  EXPECT_EQ(Run("check --bag=" + dir.File("imu_only.bag") + " >/dev/null", &output), 1);
  EXPECT_EQ(output, "tiltcal_inspect: " + dir.File("imu_only.bag") +
                        ": cannot be calibrated: LiDAR: no sensor_msgs/PointCloud2 or "
                        "livox_ros_driver/CustomMsg or livox_ros_driver2/CustomMsg topic in the "
                        "bag (topics: /imu/data)\n");
}

TEST(CheckBag, FixtureBagsRunWithoutError) {
  const std::string fixtures = testing::SharedFixturesDir();
  if (fixtures.empty() || !std::filesystem::is_directory(fixtures + "/bags/ros1")) {
    GTEST_SKIP() << "no ../shared/fixtures/bags/ros1";
  }
  int num_bags = 0;
  for (const auto& entry : std::filesystem::directory_iterator(fixtures + "/bags/ros1")) {
    if (entry.path().extension() != ".bag") continue;
    ++num_bags;
    std::ostringstream out;
    const Status status = RunCheck({entry.path().string(), ""}, Defaults(), out);
    // Either a verdict after a full report, or an error naming the bag.
    if (Contains(out.str(), "verdict: ")) {
      EXPECT_EQ(status.ok(), Contains(out.str(), "verdict: can be calibrated")) << out.str();
    }
    if (!status.ok()) {
      EXPECT_EQ(status.message().rfind(entry.path().string() + ": ", 0), 0u) << status.message();
    }
    std::printf("%s: %s\n", entry.path().filename().c_str(),
                status.ok() ? "can be calibrated" : status.message().c_str());
  }
  EXPECT_GT(num_bags, 0);
}

}  // namespace
}  // namespace tiltcal::inspect
