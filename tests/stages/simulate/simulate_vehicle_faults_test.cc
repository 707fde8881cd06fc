// The faults of real vehicles' recordings that tiltcal_simulate can add
// (SimFaultParams): consumer-grade IMU intrinsics, IMU-felt vibration, LiDAR
// clock drift, dropped scans, grass, rolling ground and walking people. Each
// is measured back from the simulated data against the truth; with every
// fault off, every scenario's bag keeps the bytes of the simulator before
// these faults existed.
#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "bag/ros1/bag_reader.h"
#include "bag/ros1/messages.h"
#include "common/geometry/angles.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/simulate/imu_schedule.h"
#include "stages/simulate/simulate.h"
#include "tests/bag/ros1/rosbag_oracle.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"

namespace tiltcal::simulate {
namespace {

using tiltcal::testing::TempDir;

std::string ScenarioPath(const std::string& name) {
  return tiltcal::testing::SourceDir() + "/stages/simulate/scenarios/" + name;
}

// Scenario file `name` with `overrides` (text format) merged over it.
proto::SimulateParams ScenarioWith(const std::string& name, const std::string& overrides) {
  std::string text;
  const Status read = ReadFileToString(ScenarioPath(name), &text);
  EXPECT_TRUE(read.ok()) << read.message();
  return tiltcal::testing::DefaultParamsWith<proto::SimulateParams>(text, overrides);
}
proto::SimulateParams ShortWith(const std::string& overrides) {
  return ScenarioWith("short_test_vlp16.txtpb", overrides);
}

struct ImuSample {
  uint32_t seq = 0;
  int64_t stamp_ns = 0;
  Eigen::Vector3d gyro, accel;
};
struct CloudHeader {
  uint32_t seq = 0;
  int64_t stamp_ns = 0;
  uint32_t crc32 = 0;  // of the serialized message
};
struct Bag {
  std::vector<ImuSample> imu;
  std::vector<CloudHeader> clouds;
};
struct SimRun {
  proto::SimulationTruth truth;
  Bag bag;
  std::string bag_path;
};

Bag ReadBag(const std::string& path, const proto::SimulateParams& params) {
  Bag bag;
  ros1::BagReader reader;
  Status status = reader.Open(path);
  EXPECT_TRUE(status.ok()) << status.message();
  if (!status.ok()) return bag;
  status = reader.ReadMessages({}, [&](const ros1::MessageView& m) -> Status {
    if (m.connection->topic == params.imu().topic()) {
      ros1::ImuMessage imu;
      TILTCAL_RETURN_IF_ERROR(ros1::DecodeImu(m.data, m.size, &imu));
      ImuSample s;
      s.seq = imu.header.seq;
      s.stamp_ns = ros1::RosTimeToNs(imu.header.stamp);
      s.gyro = Eigen::Vector3d(imu.angular_velocity[0], imu.angular_velocity[1],
                               imu.angular_velocity[2]);
      s.accel = Eigen::Vector3d(imu.linear_acceleration[0], imu.linear_acceleration[1],
                                imu.linear_acceleration[2]);
      bag.imu.push_back(s);
      return Status::Ok();
    }
    ros1::PointCloud2View cloud;
    TILTCAL_RETURN_IF_ERROR(ros1::DecodePointCloud2(m.data, m.size, &cloud));
    bag.clouds.push_back({cloud.header.seq, ros1::RosTimeToNs(cloud.header.stamp),
                          ros1::testing::Crc32(m.data, m.size)});
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
  return bag;
}

SimRun Simulate(const proto::SimulateParams& params, const TempDir& dir, const std::string& name) {
  SimulatePaths paths;
  paths.out_bag = dir.File(name + ".bag");
  paths.out_truth = dir.File(name + "_truth.txtpb");
  const Status status = simulate::Run(paths, params, /*log=*/nullptr);
  EXPECT_TRUE(status.ok()) << status.message();
  SimRun run;
  EXPECT_TRUE(ReadTextProto(paths.out_truth, &run.truth).ok());
  run.bag = ReadBag(paths.out_bag, params);
  run.bag_path = paths.out_bag;
  return run;
}

Eigen::Matrix3d MatrixOf(const proto::TruthTriadErrors& t) {
  EXPECT_EQ(t.measured_from_true_size(), 9);
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  for (int i = 0; i < std::min(9, t.measured_from_true_size()); ++i) {
    k(i / 3, i % 3) = t.measured_from_true(i);
  }
  return k;
}

// The true angular rate and specific force (frame b) of sample i.
void TrueImu(const Scenario& scenario, double rate_hz, int i, Eigen::Vector3d* omega,
             Eigen::Vector3d* force) {
  const ImuState s = scenario.trajectory->Evaluate(NominalImuStampNs(0, rate_hz, i) * 1e-9);
  *omega = s.angular_velocity_b;
  *force = s.world_from_imu.transpose() * (s.acceleration_w - scenario.gravity_w);
}

// With every fault off the bag of every scenario is byte for byte what the
// simulator wrote before these faults existed: CRC-32 and size of each
// scenario cut to 1.5 s with a short static start (so the vehicle moves),
// measured with the binary of main at 3a168b9. Empty fault messages
// (present, every field 0) change nothing either.
TEST(SimulateVehicleFaultsTest, EveryScenarioKeepsItsBytesWithFaultsOff) {
  struct Case {
    std::string file;
    uint32_t crc32;
    size_t size;
  };
  const std::vector<Case> cases = {
      {"flat_m2dgr_vlp32c.txtpb", 0x0c16d08f, 13775731},
      {"flat_vlp16.txtpb", 0x223a1ce8, 5495056},
      {"flat_vlp16_40s.txtpb", 0x10856043, 5325245},
      {"offroad_os1_32.txtpb", 0x7a613692, 7645567},
      {"short_test_vlp16.txtpb", 0xe12b821b, 6881843},
      {"tilted_husky_vlp16.txtpb", 0x39d8fca5, 5283301},
  };
  const std::string cut = "duration_s: 1.5 trajectory { static_start_s: 0.2 ramp_s: 0.3 } ";
  const std::string empty_faults =
      "faults { gyro_intrinsics { scale_ppm {} misalignment_deg {} } accel_intrinsics {} "
      "imu_vibration { when: WHILE_MOVING } pedestrians { walk: RANDOM_WAYPOINTS } }";
  TempDir dir;
  for (const Case& c : cases) {
    for (const std::string& faults : {std::string(), empty_faults}) {
      if (!faults.empty() && c.file != "short_test_vlp16.txtpb") continue;
      SCOPED_TRACE(c.file + " " + faults);
      const proto::SimulateParams params = ScenarioWith(c.file, cut + faults);
      const SimRun run = Simulate(params, dir, "off");
      std::string bytes;
      ASSERT_TRUE(ReadFileToString(run.bag_path, &bytes).ok());
      EXPECT_EQ(bytes.size(), c.size);
      EXPECT_EQ(ros1::testing::Crc32(bytes.data(), bytes.size()), c.crc32);
      EXPECT_EQ(run.truth.num_scans_dropped(), 0u);
      EXPECT_EQ(run.truth.pedestrians_size(), 0);
    }
  }
}

// Scale factors and misalignment given explicitly: every sample of the
// faulty bag minus the clean bag of the same seed (same bias and noise) is
// (K − I) times the true rate / specific force, K = I + S + M as in the
// truth; and K estimated blind by least squares from the faulty samples and
// the true trajectory (bias removed) matches the truth within 5 σ of the
// estimate. The body rocks (trajectory vibration) so that every axis turns.
TEST(SimulateVehicleFaultsTest, ImuScaleAndMisalignment) {
  TempDir dir;
  const std::string motion =
      "trajectory { vibration_roll_deg: 3 vibration_pitch_deg: 3 vibration_frequency_hz: 2 } ";
  const std::string faults =
      "faults { gyro_intrinsics { scale_ppm { x: 20000 y: -15000 z: 10000 } "
      "misalignment_deg { x: 0.5 y: -0.8 z: 1.0 } } "
      "accel_intrinsics { scale_ppm { x: -10000 y: 30000 z: 5000 } "
      "misalignment_deg { x: -1 y: 0.6 z: 0.4 } } }";
  const proto::SimulateParams clean_params = ShortWith(motion);
  const proto::SimulateParams params = ShortWith(motion + faults);
  const SimRun clean = Simulate(clean_params, dir, "clean");
  const SimRun faulty = Simulate(params, dir, "faulty");
  using geometry::kRadPerDeg;
  Eigen::Matrix3d k_gyro, k_accel;
  k_gyro << 1.02, 0, 0,
            0.5 * kRadPerDeg, 1 - 0.015, 0,
            -0.8 * kRadPerDeg, 1.0 * kRadPerDeg, 1.01;
  k_accel << 1 - 0.01, 0, 0,
             -1 * kRadPerDeg, 1.03, 0,
             0.6 * kRadPerDeg, 0.4 * kRadPerDeg, 1.005;
  EXPECT_LT((MatrixOf(faulty.truth.gyro_intrinsics()) - k_gyro).norm(), 1e-12);
  EXPECT_LT((MatrixOf(faulty.truth.accel_intrinsics()) - k_accel).norm(), 1e-12);
  EXPECT_NEAR(faulty.truth.gyro_intrinsics().scale_ppm().x(), 20000, 1e-6);
  EXPECT_NEAR(faulty.truth.accel_intrinsics().misalignment_deg().x(), -1, 1e-12);

  Scenario scenario;
  ASSERT_TRUE(BuildScenario(params, &scenario).ok());
  const double rate = params.imu().rate_hz();
  ASSERT_EQ(faulty.bag.imu.size(), clean.bag.imu.size());
  ASSERT_GT(faulty.bag.imu.size(), 700u);
  const int n = static_cast<int>(faulty.bag.imu.size());
  Eigen::MatrixXd x_gyro(n, 3), y_gyro(n, 3), x_accel(n, 3), y_accel(n, 3);
  const Eigen::Vector3d b_g = ToEigen(faulty.truth.gyro_bias_radps());
  const Eigen::Vector3d b_a = ToEigen(faulty.truth.accel_bias_mps2());
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d omega, force;
    TrueImu(scenario, rate, i, &omega, &force);
    const ImuSample& f = faulty.bag.imu[static_cast<size_t>(i)];
    const ImuSample& c = clean.bag.imu[static_cast<size_t>(i)];
    ASSERT_LT((f.gyro - c.gyro - (k_gyro - Eigen::Matrix3d::Identity()) * omega).norm(), 1e-9);
    ASSERT_LT((f.accel - c.accel - (k_accel - Eigen::Matrix3d::Identity()) * force).norm(), 1e-9);
    x_gyro.row(i) = omega.transpose();
    y_gyro.row(i) = (f.gyro - b_g).transpose();
    x_accel.row(i) = force.transpose();
    y_accel.row(i) = (f.accel - b_a).transpose();
  }
  // Blind estimate: y = x K^T + noise.
  const double sigma_g = params.imu().gyro_noise_density_radps_sqrthz() * std::sqrt(rate);
  const double sigma_a = params.imu().accel_noise_density_mps2_sqrthz() * std::sqrt(rate);
  for (const auto& [x, y, k, sigma, name] :
       {std::tuple{&x_gyro, &y_gyro, &k_gyro, sigma_g, "gyro"},
        std::tuple{&x_accel, &y_accel, &k_accel, sigma_a, "accel"}}) {
    SCOPED_TRACE(name);
    const Eigen::Matrix3d normal = x->transpose() * *x;
    const Eigen::Matrix3d k_hat = normal.ldlt().solve(x->transpose() * *y).transpose();
    const Eigen::Vector3d column_sigma = sigma * normal.inverse().diagonal().cwiseSqrt();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(k_hat(r, c), (*k)(r, c), 5 * column_sigma[c]) << r << "," << c;
        EXPECT_LT(column_sigma[c], 4e-3);  // the estimate resolves errors of 1e-2
      }
    }
  }
}

// Intrinsics drawn within bounds: the truth holds values inside the bounds
// (not all 0), K built from them, another seed draws others, and the
// gyroscope's draw does not depend on the accelerometer's bounds. The bag
// carries exactly the drawn K.
TEST(SimulateVehicleFaultsTest, ImuIntrinsicsDrawnWithinBounds) {
  TempDir dir;
  const std::string gyro = "gyro_intrinsics { scale_max_ppm: 5000 misalignment_max_deg: 0.5 } ";
  const std::string accel = "accel_intrinsics { scale_max_ppm: 3000 misalignment_max_deg: 0.2 } ";
  const proto::SimulateParams params = ShortWith("duration_s: 1 faults { " + gyro + accel + "}");
  const SimRun clean = Simulate(ShortWith("duration_s: 1"), dir, "clean");
  const SimRun run = Simulate(params, dir, "drawn");
  const SimRun other_seed =
      Simulate(ShortWith("duration_s: 1 seed: 8 faults { " + gyro + accel + "}"), dir, "seed8");
  const SimRun gyro_only = Simulate(ShortWith("duration_s: 1 faults { " + gyro + "}"), dir, "gyro");
  for (const auto& [t, max_ppm, max_deg] :
       {std::tuple{&run.truth.gyro_intrinsics(), 5000.0, 0.5},
        std::tuple{&run.truth.accel_intrinsics(), 3000.0, 0.2}}) {
    const Eigen::Vector3d scale = ToEigen(t->scale_ppm());
    const Eigen::Vector3d angles = ToEigen(t->misalignment_deg());
    EXPECT_LE(scale.cwiseAbs().maxCoeff(), max_ppm);
    EXPECT_GT(scale.cwiseAbs().minCoeff(), 0.0);
    EXPECT_LE(angles.cwiseAbs().maxCoeff(), max_deg);
    EXPECT_GT(angles.cwiseAbs().minCoeff(), 0.0);
    Eigen::Matrix3d k = Eigen::Matrix3d::Identity();
    k.diagonal() += scale * 1e-6;
    k(1, 0) = geometry::DegToRad(angles.x());
    k(2, 0) = geometry::DegToRad(angles.y());
    k(2, 1) = geometry::DegToRad(angles.z());
    EXPECT_LT((MatrixOf(*t) - k).norm(), 1e-12);
  }
  EXPECT_NE(ToEigen(other_seed.truth.gyro_intrinsics().scale_ppm()),
            ToEigen(run.truth.gyro_intrinsics().scale_ppm()));
  EXPECT_EQ(ToEigen(gyro_only.truth.gyro_intrinsics().scale_ppm()),
            ToEigen(run.truth.gyro_intrinsics().scale_ppm()));
  EXPECT_FALSE(gyro_only.truth.has_accel_intrinsics());
  Scenario scenario;
  ASSERT_TRUE(BuildScenario(params, &scenario).ok());
  const Eigen::Matrix3d k_gyro = MatrixOf(run.truth.gyro_intrinsics());
  const Eigen::Matrix3d k_accel = MatrixOf(run.truth.accel_intrinsics());
  ASSERT_EQ(run.bag.imu.size(), clean.bag.imu.size());
  for (size_t i = 0; i < run.bag.imu.size(); ++i) {
    Eigen::Vector3d omega, force;
    TrueImu(scenario, params.imu().rate_hz(), static_cast<int>(i), &omega, &force);
    const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
    const Eigen::Vector3d gyro_change = run.bag.imu[i].gyro - clean.bag.imu[i].gyro;
    const Eigen::Vector3d accel_change = run.bag.imu[i].accel - clean.bag.imu[i].accel;
    ASSERT_LT((gyro_change - (k_gyro - identity) * omega).norm(), 1e-9);
    ASSERT_LT((accel_change - (k_accel - identity) * force).norm(), 1e-9);
  }
}

// Amplitude of the DFT of `x` (sampled at `rate`) at `f`, as a sinusoid's
// amplitude (2/N |Σ x e^{−iωt}|).
double DftAmplitude(const std::vector<double>& x, double rate, double f) {
  double re = 0, im = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double phase = 2 * M_PI * f * static_cast<double>(i) / rate;
    re += x[i] * std::cos(phase);
    im -= x[i] * std::sin(phase);
  }
  return 2.0 / static_cast<double>(x.size()) * std::hypot(re, im);
}

// The frequency in [lo, hi] (step 0.05 Hz) where the DFT of x peaks.
double PeakFrequency(const std::vector<double>& x, double rate, double lo, double hi) {
  double best_f = lo, best = -1;
  for (double f = lo; f <= hi; f += 0.05) {
    const double a = DftAmplitude(x, rate, f);
    if (a > best) {
      best = a;
      best_f = f;
    }
  }
  return best_f;
}

// IMU-felt vibration: the spectrum of the faulty IMU data peaks at the
// vibration frequency, or at its alias |f − rate| above the Nyquist
// frequency; the faulty minus the clean bag is A sin(2π f t + phase) per
// axis with the truth's phases; the amplitude fitted at the peak is A;
// WHILE_MOVING is 0 through the static start and full once moving.
TEST(SimulateVehicleFaultsTest, ImuVibration) {
  TempDir dir;
  const proto::SimulateParams clean_params = ShortWith("");
  const SimRun clean = Simulate(clean_params, dir, "clean");
  const double rate = clean_params.imu().rate_hz();
  struct Case {
    double frequency_hz, seen_hz;
    std::string when;
  };
  for (const Case& c : std::vector<Case>{{37, 37, "ALWAYS"}, {230, 30, "ALWAYS"},
                                         {23, 23, "WHILE_MOVING"}}) {
    SCOPED_TRACE(c.frequency_hz);
    const double a_f = 0.5, a_w = 0.05;
    const proto::SimulateParams params = ShortWith(
        "faults { imu_vibration { frequency_hz: " + std::to_string(c.frequency_hz) +
        " accel_amplitude_mps2: 0.5 gyro_amplitude_radps: 0.05 when: " + c.when + " } }");
    const SimRun run = Simulate(params, dir, "vibration");
    ASSERT_EQ(run.bag.imu.size(), clean.bag.imu.size());
    const Eigen::Vector3d phase_w = ToEigen(run.truth.imu_vibration_gyro_phase_rad());
    const Eigen::Vector3d phase_f = ToEigen(run.truth.imu_vibration_accel_phase_rad());
    EXPECT_NE(phase_w, phase_f);
    Scenario scenario;
    ASSERT_TRUE(BuildScenario(params, &scenario).ok());
    const bool moving_only = c.when == "WHILE_MOVING";
    std::vector<double> accel_x, diff_x;  // faulty accel x; (faulty − clean) accel x, moving
    for (size_t i = 0; i < run.bag.imu.size(); ++i) {
      const double t = NominalImuStampNs(0, rate, static_cast<int>(i)) * 1e-9;
      const double w = moving_only ? scenario.trajectory->Evaluate(t).moving_rate : 1.0;
      const Eigen::Vector3d dw = run.bag.imu[i].gyro - clean.bag.imu[i].gyro;
      const Eigen::Vector3d df = run.bag.imu[i].accel - clean.bag.imu[i].accel;
      for (int a = 0; a < 3; ++a) {
        ASSERT_NEAR(dw[a], a_w * w * std::sin(2 * M_PI * c.frequency_hz * t + phase_w[a]), 1e-9);
        ASSERT_NEAR(df[a], a_f * w * std::sin(2 * M_PI * c.frequency_hz * t + phase_f[a]), 1e-9);
      }
      if (moving_only && t < params.trajectory().static_start_s()) {
        ASSERT_EQ(dw.norm() + df.norm(), 0.0);
      }
      const double moving_from_s =
          params.trajectory().static_start_s() + params.trajectory().ramp_s();
      if (!moving_only || t >= moving_from_s) {
        accel_x.push_back(run.bag.imu[i].accel.x());
        diff_x.push_back(df.x());
      }
    }
    // Blind: the spectrum of the IMU data above the motion's band.
    EXPECT_NEAR(PeakFrequency(accel_x, rate, 5, rate / 2), c.seen_hz, 0.3);
    EXPECT_NEAR(DftAmplitude(diff_x, rate, c.seen_hz), a_f, 0.03 * a_f);
  }
}

// LiDAR clock drift: every LiDAR stamp is start + t (1 + ppm 1e-6) − τ for
// its true time t, so the stamps against the true times have slope
// 1 + ppm 1e-6 and the offset at the first IMU sample is τ; the IMU stamps
// do not move.
TEST(SimulateVehicleFaultsTest, LidarClockDrift) {
  TempDir dir;
  const SimRun clean = Simulate(ShortWith(""), dir, "clean");
  for (const double ppm : {200.0, -500.0}) {
    SCOPED_TRACE(ppm);
    const proto::SimulateParams params =
        ShortWith("faults { lidar_clock_drift_ppm: " + std::to_string(ppm) + " }");
    const SimRun run = Simulate(params, dir, "drift");
    const proto::SimulationTruth& truth = run.truth;
    ASSERT_EQ(run.bag.clouds.size(), static_cast<size_t>(truth.scans_size()));
    ASSERT_GE(truth.scans_size(), 30);
    const int64_t start = truth.start_stamp_ns();
    for (int k = 0; k < truth.scans_size(); ++k) {
      const int64_t t = truth.scans(k).true_stamp_ns() - start;
      EXPECT_EQ(truth.scans(k).stamp_ns(),
                start + t + std::llround(t * ppm * 1e-6) - truth.time_offset_ns());
      EXPECT_EQ(run.bag.clouds[static_cast<size_t>(k)].stamp_ns, truth.scans(k).stamp_ns());
      EXPECT_EQ(truth.scans(k).true_stamp_ns(), clean.truth.scans(k).true_stamp_ns());
    }
    const auto& first = truth.scans(0);
    const auto& last = truth.scans(truth.scans_size() - 1);
    const double slope = static_cast<double>(last.stamp_ns() - first.stamp_ns()) /
                         static_cast<double>(last.true_stamp_ns() - first.true_stamp_ns());
    EXPECT_NEAR((slope - 1) * 1e6, ppm, 0.01);
    ASSERT_EQ(run.bag.imu.size(), clean.bag.imu.size());
    for (size_t i = 0; i < run.bag.imu.size(); ++i) {
      ASSERT_EQ(run.bag.imu[i].stamp_ns, clean.bag.imu[i].stamp_ns);
    }
  }
}

// Dropped scans: about the given fraction is missing, never the first or
// the last; those left keep their seq and bytes; the truth counts the
// dropped ones and lists the scans in the bag; the IMU is untouched.
TEST(SimulateVehicleFaultsTest, DroppedScans) {
  TempDir dir;
  const SimRun clean = Simulate(ShortWith("duration_s: 12"), dir, "clean");
  const SimRun run = Simulate(ShortWith("duration_s: 12 faults { lidar_drop_fraction: 0.3 }"), dir,
                           "dropped");
  const size_t total = clean.bag.clouds.size();
  ASSERT_GT(total, 100u);
  EXPECT_EQ(run.bag.clouds.size() + run.truth.num_scans_dropped(), total);
  EXPECT_EQ(run.bag.clouds.size(), static_cast<size_t>(run.truth.scans_size()));
  EXPECT_EQ(run.bag.clouds.front().seq, 0u);
  EXPECT_EQ(run.bag.clouds.back().seq, total - 1);
  for (size_t j = 0; j < run.bag.clouds.size(); ++j) {
    const CloudHeader& c = run.bag.clouds[j];
    ASSERT_LT(c.seq, total);
    EXPECT_EQ(c.crc32, clean.bag.clouds[c.seq].crc32);
    EXPECT_EQ(c.stamp_ns, run.truth.scans(static_cast<int>(j)).stamp_ns());
  }
  const double fraction = static_cast<double>(run.truth.num_scans_dropped()) / (total - 2);
  EXPECT_NEAR(fraction, 0.3, 4 * std::sqrt(0.3 * 0.7 / (total - 2)));
  EXPECT_EQ(run.bag.imu.size(), clean.bag.imu.size());
}

// A returned point in the simulation world w: the LiDAR pose at the point's
// firing time applied to its coordinates (Velodyne times: `time_s` after the
// stamp).
Eigen::Vector3d PointInWorld(const Scenario& scenario, const SimulatedScan& scan,
                             const ScanPoint& p, double* t_out) {
  const double t = scan.stamp_true_ns * 1e-9 + p.time_s;
  Eigen::Matrix3d c_wb;
  Eigen::Vector3d r_wb;
  scenario.trajectory->Pose(t, &c_wb, &r_wb);
  const Eigen::Matrix3d c_wl = c_wb * scenario.scan.imu_from_lidar_rotation;
  const Eigen::Vector3d r_wl = r_wb + c_wb * scenario.scan.imu_from_lidar_translation;
  if (t_out != nullptr) *t_out = t;
  return r_wl + c_wl * Eigen::Vector3d(p.x, p.y, p.z);
}

// Heights above the mean plane (along its normal) of the ground returns of
// sweeps `sweeps`, and their offsets from the world's ground surface.
void GroundHeights(const proto::SimulateParams& params, const std::vector<int>& sweeps,
                   std::vector<double>* height, std::vector<double>* above_surface) {
  Scenario scenario;
  ASSERT_TRUE(BuildScenario(params, &scenario).ok());
  const Eigen::Vector3d n = scenario.world->ground_normal();
  for (const int k : sweeps) {
    const SimulatedScan scan = SimulateSweep(scenario.scan, *scenario.trajectory,
                                             *scenario.world, params.seed(), k);
    for (const ScanPoint& p : scan.points) {
      if (p.label != static_cast<uint8_t>(Surface::kGround)) continue;
      const Eigen::Vector3d x = PointInWorld(scenario, scan, p, nullptr);
      height->push_back(n.dot(x));
      above_surface->push_back(n.dot(x) - scenario.world->GroundHeight(x));
    }
  }
}

double Rms(const std::vector<double>& x) {
  double sum2 = 0;
  for (const double v : x) sum2 += v * v;
  return std::sqrt(sum2 / static_cast<double>(x.size()));
}

// Grass: without range noise the ground returns lie on the plane (to float
// precision) and with ground_roughness_m: σ their heights have mean 0 and
// standard deviation σ; the other returns do not move.
TEST(SimulateVehicleFaultsTest, GroundRoughness) {
  std::vector<double> flat, flat_surface, rough, rough_surface;
  GroundHeights(ShortWith("lidar { range_noise_m: 0 }"), {5, 15, 30}, &flat, &flat_surface);
  GroundHeights(ShortWith("lidar { range_noise_m: 0 } faults { ground_roughness_m: 0.03 }"),
                {5, 15, 30}, &rough, &rough_surface);
  ASSERT_GT(flat.size(), 10000u);
  ASSERT_GT(rough.size(), 10000u);
  EXPECT_LT(Rms(flat), 1e-4);
  double mean = 0;
  for (const double h : rough) mean += h / static_cast<double>(rough.size());
  EXPECT_NEAR(mean, 0.0, 1e-3);
  EXPECT_NEAR(Rms(rough), 0.03, 0.03 * 0.03);
}

// Rolling ground: the ground returns lie on the undulating surface h(u, v)
// of the world (to float precision), and their heights above the mean plane
// reach ±A; the truth holds the phases.
TEST(SimulateVehicleFaultsTest, RollingGround) {
  const double amplitude = 0.15;
  const proto::SimulateParams params = ShortWith(
      "lidar { range_noise_m: 0 } faults { rolling_ground_amplitude_m: 0.15 "
      "rolling_ground_wavelength_m: 6 }");
  std::vector<double> height, above_surface;
  GroundHeights(params, {5, 15, 30}, &height, &above_surface);
  ASSERT_GT(height.size(), 10000u);
  EXPECT_LT(Rms(above_surface), 1e-4);
  EXPECT_GT(*std::max_element(height.begin(), height.end()), 0.8 * amplitude);
  EXPECT_LT(*std::min_element(height.begin(), height.end()), -0.8 * amplitude);
  EXPECT_LE(*std::max_element(height.begin(), height.end()), amplitude + 1e-4);
  EXPECT_GT(Rms(height), 0.25 * amplitude);
  TempDir dir;
  const SimRun run = Simulate(ShortWith("duration_s: 0.5 faults { rolling_ground_amplitude_m: 0.15 "
                                     "rolling_ground_wavelength_m: 6 }"),
                           dir, "rolling");
  Scenario scenario;
  ASSERT_TRUE(BuildScenario(params, &scenario).ok());
  EXPECT_EQ(run.truth.rolling_ground_phase_u_rad(), scenario.rolling_phase_u_rad);
  EXPECT_NE(run.truth.rolling_ground_phase_u_rad(), 0.0);
}

// Walking people: they walk at the given speed (1.4 m/s) along their
// waypoints (STRAIGHT_LINE: back and forth between two points); the LiDAR
// sees them (returns labelled as a person), every such return on the
// person's cylinder at its firing time, and the returns of a person move
// with it from sweep to sweep.
TEST(SimulateVehicleFaultsTest, WalkingPeople) {
  for (const std::string walk : {"RANDOM_WAYPOINTS", "STRAIGHT_LINE"}) {
    SCOPED_TRACE(walk);
    const proto::SimulateParams params =
        ShortWith("lidar { range_noise_m: 0 } faults { pedestrians { count: 5 walk: " + walk +
                  " speed_mps: 1.4 radius_m: 0.25 height_m: 1.75 } }");
    Scenario scenario;
    ASSERT_TRUE(BuildScenario(params, &scenario).ok());
    const Pedestrians& people = scenario.pedestrians;
    ASSERT_EQ(people.people().size(), 5u);
    for (size_t i = 0; i < 5; ++i) {
      const Pedestrian& person = people.people()[i];
      ASSERT_GE(person.arrival_s.back(), params.duration_s());
      if (walk == "STRAIGHT_LINE" && person.waypoints.size() > 2) {
        EXPECT_EQ(person.waypoints[2], person.waypoints[0]);
      }
      // 1.4 m/s along a leg: 0.1 s apart inside the first leg.
      const double t0 = 0.5 * person.arrival_s[1] - 0.05;
      EXPECT_NEAR((people.Position(static_cast<int>(i), t0 + 0.1) -
                   people.Position(static_cast<int>(i), t0))
                      .norm(),
                  0.14, 1e-9);
    }
    // Person returns per sweep and person: their mean position in w.
    std::vector<std::vector<Eigen::Vector2d>> centroid(5);
    std::vector<std::vector<double>> sweep_time(5);
    int returns = 0;
    for (int k = 0; k < 39; k += 2) {
      const SimulatedScan scan = SimulateSweep(scenario.scan, *scenario.trajectory,
                                               *scenario.world, params.seed(), k, &people);
      std::vector<Eigen::Vector2d> sum(5, Eigen::Vector2d::Zero());
      std::vector<int> count(5, 0);
      for (const ScanPoint& p : scan.points) {
        if (p.label != static_cast<uint8_t>(Surface::kPerson)) continue;
        double t;
        const Eigen::Vector3d x = PointInWorld(scenario, scan, p, &t);
        // The person whose cylinder the return lies on.
        int on = -1;
        for (int i = 0; i < 5; ++i) {
          const Eigen::Vector2d c = people.Position(i, t);
          if (std::abs((x.head<2>() - c).norm() - 0.25) < 1e-3 &&
              x.z() <= scenario.world->GroundZ(c.x(), c.y()) + 1.75 + 1e-3) {
            on = i;
          }
        }
        ASSERT_GE(on, 0) << "a person return on no person's cylinder";
        sum[static_cast<size_t>(on)] += x.head<2>();
        ++count[static_cast<size_t>(on)];
        ++returns;
      }
      for (size_t i = 0; i < 5; ++i) {
        if (count[i] < 20) continue;
        centroid[i].push_back(sum[i] / count[i]);
        sweep_time[i].push_back(scan.stamp_true_ns * 1e-9);
      }
    }
    EXPECT_GT(returns, 500);
    // Seen in two sweeps at least 1 s apart, the returns moved with the
    // person (within the radius and the change of viewpoint).
    int checked = 0;
    for (size_t i = 0; i < 5; ++i) {
      if (centroid[i].size() < 2) continue;
      const size_t a = 0, b = centroid[i].size() - 1;
      if (sweep_time[i][b] - sweep_time[i][a] < 1.0) continue;
      const Eigen::Vector2d moved = people.Position(static_cast<int>(i), sweep_time[i][b]) -
                                    people.Position(static_cast<int>(i), sweep_time[i][a]);
      EXPECT_GT(moved.norm(), 0.5);
      EXPECT_LT((centroid[i][b] - centroid[i][a] - moved).norm(), 0.4);
      ++checked;
    }
    EXPECT_GE(checked, 1);
  }
}

// Values the schema cannot check: one error naming the field.
TEST(SimulateVehicleFaultsTest, BadFaultParamsAreAClearError) {
  for (const auto& [overrides, field] : std::vector<std::pair<std::string, std::string>>{
           {"faults { imu_vibration { accel_amplitude_mps2: 1 } }",
            "faults.imu_vibration.frequency_hz"},
           {"faults { rolling_ground_amplitude_m: 0.1 }", "faults.rolling_ground_wavelength_m"},
           {"faults { pedestrians { count: 2 speed_mps: 1.4 radius_m: 0.25 } }",
            "faults.pedestrians.height_m"},
           {"faults { gyro_intrinsics { scale_ppm { y: 200000 } } }",
            "faults.gyro_intrinsics.scale_ppm"},
           {"faults { accel_intrinsics { misalignment_deg { z: 4 } misalignment_max_deg: 2 } }",
            "faults.accel_intrinsics.misalignment_deg"}}) {
    SCOPED_TRACE(overrides);
    Scenario scenario;
    const Status status = BuildScenario(ShortWith(overrides), &scenario);
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.message().find(field), std::string::npos) << status.message();
  }
}

// The fault scenario of scenarios/ (every fault of a worn vehicle at once),
// cut to 5 s: its truth holds what the faults drew.
TEST(SimulateVehicleFaultsTest, FaultyVehicleScenario) {
  TempDir dir;
  const proto::SimulateParams params =
      ScenarioWith("faulty_vehicle_vlp16_40s.txtpb", "duration_s: 5 num_threads: 2");
  const SimRun run = Simulate(params, dir, "faulty");
  const proto::SimulationTruth& truth = run.truth;
  EXPECT_NE(MatrixOf(truth.gyro_intrinsics()), Eigen::Matrix3d::Identity());
  EXPECT_NE(MatrixOf(truth.accel_intrinsics()), Eigen::Matrix3d::Identity());
  EXPECT_NE(ToEigen(truth.imu_vibration_accel_phase_rad()), Eigen::Vector3d::Zero());
  EXPECT_EQ(truth.pedestrians_size(), static_cast<int>(params.faults().pedestrians().count()));
  EXPECT_EQ(truth.faults().lidar_clock_drift_ppm(), params.faults().lidar_clock_drift_ppm());
  EXPECT_EQ(run.bag.clouds.size(), static_cast<size_t>(truth.scans_size()));
  EXPECT_GT(truth.num_scans_dropped(), 0u);
}

}  // namespace
}  // namespace tiltcal::simulate
