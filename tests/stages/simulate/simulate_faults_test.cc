// The faults of real recordings that tiltcal_simulate can write into a bag
// (SimFaultParams, rig.time_offset_s of any size, rig_file errors of any
// angle, the IMU rate, end-stamped Velodyne sweeps): each one read back from
// the bag with our ROS 1 reader (bag/ros1/) — and the IMU faults with the
// real ROS library too — and, with every fault off, the bag bytes of before.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include "bag/ros1/bag_reader.h"
#include "bag/ros1/messages.h"
#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/imu/imu_units.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/params.h"
#include "common/io/rig.h"
#include "common/io/text_proto.h"
#include "stages/simulate/imu_schedule.h"
#include "stages/simulate/simulate.h"
#include "tests/bag/ros1/rosbag_oracle.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::simulate {
namespace {

using tiltcal::testing::TempDir;

// The short test scenario with `overrides` (text format) merged over it.
proto::SimulateParams ShortScenarioWith(const std::string& overrides) {
  std::string text;
  const Status read = ReadFileToString(
      tiltcal::testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb", &text);
  EXPECT_TRUE(read.ok()) << read.message();
  return tiltcal::testing::DefaultParamsWith<proto::SimulateParams>(text, overrides);
}

struct SimulatedRun {
  proto::SimulationTruth truth;
  std::string bag;
  std::string rig;
};

// Runs the simulator into `dir`; the outputs are named after `name`.
SimulatedRun Simulate(const proto::SimulateParams& params, const TempDir& dir,
                      const std::string& name) {
  SimulatePaths paths;
  paths.out_bag = dir.File(name + ".bag");
  paths.out_truth = dir.File(name + "_truth.txtpb");
  paths.out_rig = dir.File(name + "_rig.txtpb");
  const Status status = Run(paths, params, /*log=*/nullptr);
  EXPECT_TRUE(status.ok()) << status.message();
  SimulatedRun run;
  EXPECT_TRUE(ReadTextProto(paths.out_truth, &run.truth).ok());
  run.bag = paths.out_bag;
  run.rig = paths.out_rig;
  return run;
}

// One PointCloud2 of a bag: header, record time, the `time` field of every
// point (Velodyne layout, FLOAT32 at byte 18) and its xyz.
struct CloudRecord {
  int64_t record_ns = 0;
  int64_t stamp_ns = 0;
  uint32_t seq = 0;
  std::vector<float> time_s;
  std::vector<Eigen::Vector3f> xyz;
  uint32_t crc32 = 0;  // of the serialized message
};
struct ImuRecord {
  int64_t record_ns = 0;
  ros1::ImuMessage message;
};
struct BagContents {
  std::vector<ImuRecord> imu;
  std::vector<CloudRecord> clouds;
};

// Every message of `path` as our reader decodes it, in record-time order.
BagContents ReadBag(const std::string& path, const proto::SimulateParams& params) {
  BagContents contents;
  ros1::BagReader reader;
  Status status = reader.Open(path);
  EXPECT_TRUE(status.ok()) << status.message();
  if (!status.ok()) return contents;
  ros1::PointCloud2View cloud;
  status = reader.ReadMessages({}, [&](const ros1::MessageView& m) -> Status {
    if (m.connection->topic == params.imu().topic()) {
      ImuRecord record;
      record.record_ns = m.time_ns;
      TILTCAL_RETURN_IF_ERROR(ros1::DecodeImu(m.data, m.size, &record.message));
      contents.imu.push_back(record);
      return Status::Ok();
    }
    TILTCAL_RETURN_IF_ERROR(ros1::DecodePointCloud2(m.data, m.size, &cloud));
    CloudRecord record;
    record.record_ns = m.time_ns;
    record.stamp_ns = ros1::RosTimeToNs(cloud.header.stamp);
    record.seq = cloud.header.seq;
    record.crc32 = ros1::testing::Crc32(m.data, m.size);
    const uint32_t n = cloud.width * cloud.height;
    for (uint32_t i = 0; i < n; ++i) {
      const uint8_t* p = cloud.data + static_cast<size_t>(i) * cloud.point_step;
      float xyz[3], t;
      std::memcpy(xyz, p, sizeof(xyz));
      std::memcpy(&t, p + 18, sizeof(t));
      record.xyz.emplace_back(xyz[0], xyz[1], xyz[2]);
      record.time_s.push_back(t);
    }
    contents.clouds.push_back(std::move(record));
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
  return contents;
}

int64_t StampNs(const ros1::Header& header) { return ros1::RosTimeToNs(header.stamp); }
Eigen::Vector3d Gyro(const ros1::ImuMessage& m) {
  return Eigen::Vector3d(m.angular_velocity[0], m.angular_velocity[1], m.angular_velocity[2]);
}
Eigen::Vector3d Accel(const ros1::ImuMessage& m) {
  return Eigen::Vector3d(m.linear_acceleration[0], m.linear_acceleration[1],
                         m.linear_acceleration[2]);
}
Eigen::Matrix3d ToRotation(const proto::Rigid3& t) {
  return ToEigen(t.rotation()).toRotationMatrix();
}

// With every fault off, the bag is byte for byte the one tiltcal_simulate
// wrote before the faults existed: CRC-32 and size of the short scenario cut
// to 1 s, measured once with the binary of that version (main at b65b867).
// An all-default `faults {}` message changes nothing either.
TEST(SimulateFaultsTest, FaultsOffKeepTheBagBytes) {
  TempDir dir;
  constexpr uint32_t kCrc32 = 0x34f052c0;
  constexpr size_t kSize = 4421494;
  for (const std::string overrides : {"duration_s: 1", "duration_s: 1 faults {}"}) {
    SCOPED_TRACE(overrides);
    const proto::SimulateParams params = ShortScenarioWith(overrides);
    EXPECT_EQ(params.has_faults(), overrides.find("faults") != std::string::npos);
    const SimulatedRun run = Simulate(params, dir, "off");
    std::string bytes;
    ASSERT_TRUE(ReadFileToString(run.bag, &bytes).ok());
    EXPECT_EQ(bytes.size(), kSize);
    EXPECT_EQ(ros1::testing::Crc32(bytes.data(), bytes.size()), kCrc32);
    EXPECT_EQ(run.truth.num_imu_samples_dropped(), 0u);
    EXPECT_EQ(run.truth.imu_clock_shift_ns(), 0);
    EXPECT_EQ(run.truth.time_offset_ns(), 12500000);
  }
}

// τ far beyond the old ±1 s, both signs: every LiDAR stamp is the IMU-clock
// time of its sweep minus τ exactly, the IMU stamps do not move, and the
// truth records τ to the nanosecond. A LiDAR clock that would go below zero
// (start_stamp_ns 0, τ = +600 s) moves the IMU clock instead, and the truth
// says by how much.
TEST(SimulateFaultsTest, TimeOffsetOfAnySize) {
  TempDir dir;
  struct Case {
    std::string overrides;
    int64_t tau_ns;
    int64_t imu_clock_shift_ns;
  };
  const std::vector<Case> cases = {
      {"rig { time_offset_s: 0.08 }", 80000000, 0},
      {"rig { time_offset_s: 2.000000123 }", 2000000123, 0},
      {"rig { time_offset_s: -86400 }", -86400000000000, 0},
      {"rig { time_offset_s: 86400 }", 86400000000000, 0},
      {"start_stamp_ns: 0 rig { time_offset_s: 600 }", 600000000000, 600000000000},
      {"start_stamp_ns: 0 rig { time_offset_s: -600 }", -600000000000, 0},
  };
  std::vector<int64_t> true_times;  // sweep times since the first IMU sample, the same for all
  for (const Case& c : cases) {
    SCOPED_TRACE(c.overrides);
    const proto::SimulateParams params = ShortScenarioWith("duration_s: 0.6 " + c.overrides);
    const SimulatedRun run = Simulate(params, dir, "tau");
    const proto::SimulationTruth& truth = run.truth;
    EXPECT_EQ(truth.time_offset_ns(), c.tau_ns);
    EXPECT_EQ(std::llround(truth.time_offset_s() * 1e9), c.tau_ns);
    EXPECT_EQ(truth.imu_clock_shift_ns(), c.imu_clock_shift_ns);
    EXPECT_EQ(truth.start_stamp_ns(), params.start_stamp_ns() + c.imu_clock_shift_ns);
    const BagContents bag = ReadBag(run.bag, params);
    ASSERT_EQ(bag.imu.size(), truth.num_imu_samples());
    for (size_t i = 0; i < bag.imu.size(); ++i) {
      ASSERT_EQ(StampNs(bag.imu[i].message.header),
                NominalImuStampNs(truth.start_stamp_ns(), params.imu().rate_hz(),
                                  static_cast<int>(i)));
    }
    ASSERT_EQ(bag.clouds.size(), static_cast<size_t>(truth.scans_size()));
    ASSERT_GE(bag.clouds.size(), 4u);
    std::vector<int64_t> times;
    for (size_t k = 0; k < bag.clouds.size(); ++k) {
      const proto::TruthScan& ts = truth.scans(static_cast<int>(k));
      EXPECT_EQ(bag.clouds[k].stamp_ns, ts.stamp_ns());
      EXPECT_EQ(bag.clouds[k].record_ns, ts.stamp_ns());
      EXPECT_GE(ts.stamp_ns(), 0);
      EXPECT_EQ(ts.true_stamp_ns() - ts.stamp_ns(), c.tau_ns);
      times.push_back(ts.true_stamp_ns() - truth.start_stamp_ns());
    }
    if (true_times.empty()) true_times = times;
    EXPECT_EQ(times, true_times);
  }
  // Beyond a day: the schema refuses it, naming the field.
  proto::SimulateParams params = ShortScenarioWith("");
  params.mutable_rig()->set_time_offset_s(86401);
  const Status status = ValidateAgainstSchema(params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("rig.time_offset_s"), std::string::npos) << status.message();
}

// An IMU published in g and deg/s: every value and covariance is the SI
// value divided by 9.80665 m/s² / (π/180) rad/s; stamps and clouds are
// unchanged; the truth says which units the bag has and stays in SI.
TEST(SimulateFaultsTest, ImuInGAndDegreesPerSecond) {
  TempDir dir;
  const proto::SimulateParams si_params = ShortScenarioWith("duration_s: 1");
  const SimulatedRun si = Simulate(si_params, dir, "si");
  const BagContents si_bag = ReadBag(si.bag, si_params);
  ASSERT_GT(si_bag.imu.size(), 150u);
  struct Case {
    std::string overrides;
    double gyro_factor;   // published / SI
    double accel_factor;
  };
  const double per_g = 1.0 / imu::kStandardGravityMps2;
  for (const Case& c : std::vector<Case>{
           {"faults { imu_accel_unit: G imu_gyro_unit: DEGPS }", geometry::kDegPerRad, per_g},
           {"faults { imu_accel_unit: G }", 1.0, per_g},
           {"faults { imu_gyro_unit: DEGPS }", geometry::kDegPerRad, 1.0}}) {
    SCOPED_TRACE(c.overrides);
    const proto::SimulateParams params = ShortScenarioWith("duration_s: 1 " + c.overrides);
    const SimulatedRun run = Simulate(params, dir, "units");
    EXPECT_EQ(run.truth.faults().imu_accel_unit(), params.faults().imu_accel_unit());
    EXPECT_EQ(run.truth.faults().imu_gyro_unit(), params.faults().imu_gyro_unit());
    EXPECT_EQ(run.truth.gravity_flat_in_imu().z(), si.truth.gravity_flat_in_imu().z());  // SI
    const BagContents bag = ReadBag(run.bag, params);
    ASSERT_EQ(bag.imu.size(), si_bag.imu.size());
    std::vector<double> norms;
    for (size_t i = 0; i < bag.imu.size(); ++i) {
      const ros1::ImuMessage& m = bag.imu[i].message;
      const ros1::ImuMessage& s = si_bag.imu[i].message;
      ASSERT_EQ(StampNs(m.header), StampNs(s.header));
      ASSERT_LT((Gyro(m) - c.gyro_factor * Gyro(s)).norm(), 1e-12 * c.gyro_factor);
      ASSERT_LT((Accel(m) - c.accel_factor * Accel(s)).norm(), 1e-12 * c.accel_factor * 10);
      ASSERT_NEAR(m.angular_velocity_covariance[0],
                  s.angular_velocity_covariance[0] * c.gyro_factor * c.gyro_factor, 1e-15);
      ASSERT_NEAR(m.linear_acceleration_covariance[0],
                  s.linear_acceleration_covariance[0] * c.accel_factor * c.accel_factor, 1e-15);
      norms.push_back(Accel(m).norm());
    }
    // What a unit detector sees: the median |f| is g in the published unit.
    std::nth_element(norms.begin(), norms.begin() + norms.size() / 2, norms.end());
    EXPECT_NEAR(norms[norms.size() / 2], params.gravity_norm_mps2() * c.accel_factor,
                0.05 * c.accel_factor * params.gravity_norm_mps2());
    ASSERT_EQ(bag.clouds.size(), si_bag.clouds.size());
    for (size_t k = 0; k < bag.clouds.size(); ++k) {
      EXPECT_EQ(bag.clouds[k].crc32, si_bag.clouds[k].crc32);
    }
  }
}

// IMU stamp jitter: stamps are the nominal times plus noise of the given σ,
// strictly increasing (also when σ is several sample periods), while the
// values are those of the stamp-exact bag (the samples are taken at their
// nominal times).
TEST(SimulateFaultsTest, ImuStampJitter) {
  TempDir dir;
  const proto::SimulateParams exact_params = ShortScenarioWith("");
  const BagContents exact = ReadBag(Simulate(exact_params, dir, "exact").bag, exact_params);
  for (const double sigma_s : {0.0005, 0.02}) {
    SCOPED_TRACE(sigma_s);
    const proto::SimulateParams params =
        ShortScenarioWith("faults { imu_stamp_jitter_s: " + std::to_string(sigma_s) + " }");
    const SimulatedRun run = Simulate(params, dir, "jitter");
    EXPECT_EQ(run.truth.faults().imu_stamp_jitter_s(), sigma_s);
    const BagContents bag = ReadBag(run.bag, params);
    ASSERT_EQ(bag.imu.size(), exact.imu.size());
    double sum = 0.0, sum2 = 0.0;
    int64_t min_step_ns = INT64_MAX;
    for (size_t i = 0; i < bag.imu.size(); ++i) {
      const ros1::ImuMessage& m = bag.imu[i].message;
      ASSERT_EQ(m.header.seq, i);
      ASSERT_EQ(bag.imu[i].record_ns, StampNs(m.header));
      ASSERT_EQ(Gyro(m), Gyro(exact.imu[i].message));
      ASSERT_EQ(Accel(m), Accel(exact.imu[i].message));
      const double jitter_s = (StampNs(m.header) - StampNs(exact.imu[i].message.header)) * 1e-9;
      sum += jitter_s;
      sum2 += jitter_s * jitter_s;
      if (i > 0) {
        min_step_ns = std::min(min_step_ns, StampNs(m.header) - StampNs(bag.imu[i - 1].message.header));
      }
    }
    EXPECT_GE(min_step_ns, 1000);  // strictly increasing, by 1 µs at least
    const double n = static_cast<double>(bag.imu.size());
    if (sigma_s < 0.001) {  // no clamping at 0.1 periods: the plain Gaussian
      EXPECT_NEAR(sum / n, 0.0, 4 * sigma_s / std::sqrt(n));
      EXPECT_NEAR(std::sqrt(sum2 / n), sigma_s, 0.1 * sigma_s);
      EXPECT_GT(min_step_ns, 1000000);  // 5 ms period minus a few σ
    } else {
      EXPECT_EQ(min_step_ns, 1000);  // clamped somewhere
      EXPECT_GT(std::sqrt(sum2 / n), 0.5 * sigma_s);
    }
  }
}

// Samples left out at random and in a gap: the first and last stay, the
// others are gone at the given rate and throughout the gap; the samples
// left keep their values, stamps and seq (= sample index, so the gap shows).
TEST(SimulateFaultsTest, DroppedImuSamples) {
  TempDir dir;
  const proto::SimulateParams exact_params = ShortScenarioWith("");
  const BagContents exact = ReadBag(Simulate(exact_params, dir, "exact").bag, exact_params);
  const proto::SimulateParams params = ShortScenarioWith(
      "faults { imu_drop_fraction: 0.2 imu_gaps { start_s: 1.0 duration_s: 0.25 } }");
  const SimulatedRun run = Simulate(params, dir, "drops");
  const BagContents bag = ReadBag(run.bag, params);
  const double rate = params.imu().rate_hz();
  EXPECT_EQ(bag.imu.size(), run.truth.num_imu_samples());
  EXPECT_EQ(bag.imu.size() + run.truth.num_imu_samples_dropped(), exact.imu.size());
  ASSERT_GT(bag.imu.size(), 100u);
  EXPECT_EQ(bag.imu.front().message.header.seq, 0u);
  EXPECT_EQ(bag.imu.back().message.header.seq, exact.imu.size() - 1);
  std::vector<bool> present(exact.imu.size(), false);
  for (const ImuRecord& r : bag.imu) {
    const uint32_t i = r.message.header.seq;
    ASSERT_LT(i, exact.imu.size());
    present[i] = true;
    ASSERT_EQ(StampNs(r.message.header), StampNs(exact.imu[i].message.header));
    ASSERT_EQ(Gyro(r.message), Gyro(exact.imu[i].message));
    ASSERT_EQ(Accel(r.message), Accel(exact.imu[i].message));
  }
  int outside_gap = 0, dropped_outside_gap = 0;
  for (size_t i = 1; i + 1 < present.size(); ++i) {
    const double t = i / rate;
    if (t >= 1.0 && t < 1.25) {
      EXPECT_FALSE(present[i]) << i;
    } else {
      ++outside_gap;
      dropped_outside_gap += present[i] ? 0 : 1;
    }
  }
  const double fraction = static_cast<double>(dropped_outside_gap) / outside_gap;
  EXPECT_NEAR(fraction, 0.2, 4 * std::sqrt(0.2 * 0.8 / outside_gap));
  // The largest hole between stamps is the gap (plus a sample each side).
  int64_t max_step = 0;
  for (size_t j = 1; j < bag.imu.size(); ++j) {
    max_step = std::max(max_step, bag.imu[j].record_ns - bag.imu[j - 1].record_ns);
  }
  EXPECT_GE(max_step, 260000000);
  EXPECT_LT(max_step, 300000000);
}

// The real ROS library reads a bag with every IMU fault at once (units,
// jitter, drops, 100 Hz): the stamps, seq and values it sees are those of
// our reader.
TEST(SimulateFaultsTest, RealRosLibraryReadsTheImuFaults) {
  if (!tiltcal::testing::HaveRosbagPython()) {
    GTEST_SKIP() << "Debian python3-rosbag (/usr/bin/python3) is not installed";
  }
  TempDir dir;
  const proto::SimulateParams params = ShortScenarioWith(
      "duration_s: 2 imu { rate_hz: 100 } faults { imu_accel_unit: G imu_gyro_unit: DEGPS "
      "imu_stamp_jitter_s: 0.001 imu_drop_fraction: 0.1 imu_gaps { start_s: 0.5 duration_s: 0.1 } "
      "}");
  const SimulatedRun run = Simulate(params, dir, "all");
  const BagContents ours = ReadBag(run.bag, params);
  ros1::testing::BagDump dump;
  std::string error;
  ASSERT_TRUE(ros1::testing::DumpBagWithRosbag(run.bag, dir.File("dump.txt"), {}, &dump, &error))
      << error;
  const auto imu = dump.Topic(params.imu().topic());
  ASSERT_EQ(imu.size(), ours.imu.size());
  ASSERT_EQ(imu.size(), run.truth.num_imu_samples());
  EXPECT_GT(run.truth.num_imu_samples_dropped(), 10u);
  for (size_t i = 0; i < imu.size(); ++i) {
    const ros1::ImuMessage& m = ours.imu[i].message;
    ASSERT_EQ(imu[i]->seq, m.header.seq);
    ASSERT_EQ(imu[i]->stamp_ns, StampNs(m.header));
    ASSERT_EQ(imu[i]->record_ns, StampNs(m.header));
    for (int a = 0; a < 3; ++a) {
      ASSERT_EQ(imu[i]->imu[a], m.angular_velocity[a]);
      ASSERT_EQ(imu[i]->imu[3 + a], m.linear_acceleration[a]);
    }
  }
  // g and deg/s: the static start reads about 1 g, and turning reads
  // degrees per second.
  EXPECT_NEAR(Accel(ours.imu.front().message).norm(), 1.0, 0.02);
}

// A 100 Hz IMU: one sample every 10 ms, floor(duration · rate) + 1 samples.
TEST(SimulateFaultsTest, Imu100Hz) {
  TempDir dir;
  const proto::SimulateParams params = ShortScenarioWith("duration_s: 2 imu { rate_hz: 100 }");
  const SimulatedRun run = Simulate(params, dir, "imu100");
  const BagContents bag = ReadBag(run.bag, params);
  ASSERT_EQ(bag.imu.size(), 201u);
  EXPECT_EQ(run.truth.num_imu_samples(), 201u);
  for (size_t i = 0; i < bag.imu.size(); ++i) {
    ASSERT_EQ(StampNs(bag.imu[i].message.header),
              params.start_stamp_ns() + static_cast<int64_t>(i) * 10000000);
  }
  // Per-sample σ follows the rate: density² · 100 Hz.
  EXPECT_DOUBLE_EQ(bag.imu[0].message.angular_velocity_covariance[0],
                   std::pow(params.imu().gyro_noise_density_radps_sqrthz(), 2) * 100);
}

// Velodyne stamps at the end of the sweep (the driver's default): the header
// stamp is the time of the last firing, so every point time is ≤ 0 and the
// first is one sweep span before the stamp. Stamped at the start instead,
// the same points have times ≥ 0 and the stamp is earlier by that span.
TEST(SimulateFaultsTest, VelodyneStampAtScanEnd) {
  TempDir dir;
  const proto::SimulateParams end_params = ShortScenarioWith("duration_s: 0.6");
  const proto::SimulateParams start_params =
      ShortScenarioWith("duration_s: 0.6 lidar { velodyne_stamp_at_start: true }");
  const BagContents end = ReadBag(Simulate(end_params, dir, "end").bag, end_params);
  const BagContents start = ReadBag(Simulate(start_params, dir, "start").bag, start_params);
  Scenario scenario;
  ASSERT_TRUE(BuildScenario(end_params, &scenario).ok());
  const double span_s = SweepSpanS(scenario.scan);
  EXPECT_NEAR(span_s, 0.1, 0.001);
  ASSERT_EQ(end.clouds.size(), start.clouds.size());
  ASSERT_GE(end.clouds.size(), 4u);
  for (size_t k = 0; k < end.clouds.size(); ++k) {
    SCOPED_TRACE(k);
    const CloudRecord& e = end.clouds[k];
    const CloudRecord& s = start.clouds[k];
    EXPECT_EQ(e.stamp_ns - s.stamp_ns, std::llround(span_s * 1e9));
    ASSERT_EQ(e.time_s.size(), s.time_s.size());
    ASSERT_GT(e.time_s.size(), 10000u);
    const auto [e_min, e_max] = std::minmax_element(e.time_s.begin(), e.time_s.end());
    EXPECT_LE(*e_max, 0.0f);
    EXPECT_NEAR(*e_max, 0.0, 0.002);
    EXPECT_NEAR(*e_min, -span_s, 0.002);
    EXPECT_GE(*std::min_element(s.time_s.begin(), s.time_s.end()), 0.0f);
    for (size_t i = 0; i < e.time_s.size(); ++i) {
      ASSERT_EQ(e.xyz[i], s.xyz[i]);  // the same firings from the same poses
      ASSERT_NEAR(e.time_s[i] + span_s, s.time_s[i], 1e-6);
    }
  }
}

// Rig files with mistakes of any size: a yaw wrong by 90 deg, an IMU upside
// down and not declared (180 deg about the IMU's x), a LiDAR-side error and
// a lever arm wrong by a metre, exactly as asked, and loadable by LoadRig.
TEST(SimulateFaultsTest, RigFileWithLargeErrors) {
  TempDir dir;
  struct Case {
    std::string rig_file;
    Eigen::Vector3d imu_side_deg, lidar_side_deg, translation_m;
    double angle_deg;
  };
  const std::vector<Case> cases = {
      {"rotation_error_in_imu_deg { z: 90 }", {0, 0, 90}, {0, 0, 0}, {0, 0, 0}, 90},
      {"rotation_error_in_imu_deg { x: 180 }", {180, 0, 0}, {0, 0, 0}, {0, 0, 0}, 180},
      {"rotation_error_deg { z: -90 } translation_error_m { x: 1 y: -0.5 z: 0.3 }",
       {0, 0, 0}, {0, 0, -90}, {1, -0.5, 0.3}, 90},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.rig_file);
    proto::SimulateParams params = ShortScenarioWith("duration_s: 0.3");
    params.mutable_rig_file()->clear_rotation_error_deg();
    params.mutable_rig_file()->clear_translation_error_m();
    google::protobuf::TextFormat::Parser parser;
    ASSERT_TRUE(parser.MergeFromString(c.rig_file, params.mutable_rig_file()));
    ASSERT_TRUE(ValidateAgainstSchema(params).ok());
    const SimulatedRun run = Simulate(params, dir, "rig");
    proto::Rig rig;
    const Status loaded = LoadRig(run.rig, &rig);
    ASSERT_TRUE(loaded.ok()) << loaded.message();
    const Eigen::Matrix3d c_bl = ToRotation(run.truth.imu_from_lidar());
    const Eigen::Matrix3d expected = geometry::RotationFromEuler123Deg(c.imu_side_deg) * c_bl *
                                     geometry::RotationFromEuler123Deg(c.lidar_side_deg);
    const Eigen::Matrix3d c_meas = ToRotation(rig.imu_from_lidar());
    EXPECT_LT((c_meas - expected).norm(), 1e-9);
    EXPECT_NEAR(geometry::RadToDeg(Eigen::AngleAxisd(c_bl.transpose() * c_meas).angle()),
                c.angle_deg, 1e-6);
    const Eigen::Vector3d dr = ToEigen(rig.imu_from_lidar().translation()) -
                               ToEigen(run.truth.imu_from_lidar().translation());
    EXPECT_LT((dr - c.translation_m).norm(), 1e-12);
  }
}

// Gaps that cannot be: a zero duration, or a start after the end; one
// error naming the field, no output.
TEST(SimulateFaultsTest, BadGapsAreAClearError) {
  TempDir dir;
  SimulatePaths paths;
  paths.out_bag = dir.File("x.bag");
  paths.out_truth = dir.File("x.txtpb");
  for (const auto& [overrides, field] : std::vector<std::pair<std::string, std::string>>{
           {"faults { imu_gaps { start_s: 1 duration_s: 0 } }", "faults.imu_gaps[0].duration_s"},
           {"faults { imu_gaps { start_s: 1 duration_s: 1 } imu_gaps { start_s: 9 duration_s: 1 } }",
            "faults.imu_gaps[1].start_s"}}) {
    SCOPED_TRACE(overrides);
    const Status status = simulate::Run(paths, ShortScenarioWith(overrides), nullptr);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find(field), std::string::npos) << status.message();
    EXPECT_FALSE(tiltcal::testing::FileExists(paths.out_bag));
    EXPECT_FALSE(tiltcal::testing::FileExists(paths.out_truth));
  }
  // The command line: one line naming the scenario file and the field, exit 1.
  const std::string tool = tiltcal::testing::ToolPath("tiltcal_simulate");
  if (!tiltcal::testing::FileExists(tool)) GTEST_SKIP() << "build the tiltcal_simulate target";
  const std::string scenario = dir.File("bad_gap.txtpb");
  ASSERT_TRUE(
      WriteTextProto(scenario, ShortScenarioWith("faults { imu_gaps { start_s: 2 } }")).ok());
  std::string output;
  EXPECT_EQ(tiltcal::testing::RunCommand(tool + " --params=" + scenario + " --out_bag=" +
                                             paths.out_bag + " --out_truth=" + paths.out_truth,
                                         &output),
            1);
  EXPECT_EQ(output, "tiltcal_simulate: " + scenario +
                        ": field faults.imu_gaps[0].duration_s = 0 must be > 0\n");
  EXPECT_FALSE(tiltcal::testing::FileExists(paths.out_bag));
  EXPECT_FALSE(tiltcal::testing::FileExists(paths.out_truth));
}

}  // namespace
}  // namespace tiltcal::simulate
