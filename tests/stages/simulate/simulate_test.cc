// tiltcal_simulate end to end on short scenarios: the real ROS library reads
// every message of the bags; tiltcal_decode reads them back; the simulated
// gyro integrates to the true attitude; ground points fit the true plane
// within the range noise; a seed fixes the bytes.
#include "stages/simulate/simulate.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "bag/ros1/message_encoding.h"
#include "common/geometry/angles.h"
#include "common/io/atomic_file.h"
#include "common/io/params.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "stages/simulate/point_cloud_layout.h"
#include "tests/bag/ros1/rosbag_oracle.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::simulate {
namespace {

using ros1::testing::BagDump;
using ros1::testing::Crc32;
using ros1::testing::DumpBagWithRosbag;
using ros1::testing::DumpedMessage;
using tiltcal::testing::TempDir;

proto::SimulateParams ShortScenario() {
  proto::SimulateParams params;
  const Status status = LoadParams(
      tiltcal::testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb", &params);
  EXPECT_TRUE(status.ok()) << status.message();
  return params;
}

// Runs the simulator; returns the truth.
proto::SimulationTruth Simulate(const proto::SimulateParams& params, const TempDir& dir,
                                const std::string& name) {
  SimulatePaths paths;
  paths.out_bag = dir.File(name + ".bag");
  paths.out_truth = dir.File(name + "_truth.txtpb");
  paths.out_rig = dir.File(name + "_rig.txtpb");
  const Status status = Run(paths, params, /*log=*/nullptr);
  EXPECT_TRUE(status.ok()) << status.message();
  proto::SimulationTruth truth;
  EXPECT_TRUE(ReadTextProto(paths.out_truth, &truth).ok());
  return truth;
}

Eigen::Matrix3d ToRotation(const proto::Rigid3& t) {
  return Eigen::Quaterniond(t.rotation().w(), t.rotation().x(), t.rotation().y(),
                           t.rotation().z())
      .toRotationMatrix();
}
Eigen::Vector3d ToVector(const proto::Vector3& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

Eigen::Matrix3d Exp(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, phi / angle).toRotationMatrix();
}
double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

bool NeedRosbag() { return tiltcal::testing::HaveRosbagPython(); }
#define SKIP_WITHOUT_ROSBAG()                                                         \
  if (!NeedRosbag()) GTEST_SKIP() << "Debian python3-rosbag (/usr/bin/python3) is not " \
                                     "installed"

class SimulateRosbagTest : public ::testing::TestWithParam<proto::SimBagParams::Compression> {};

// Every message of a simulated bag, as the real ROS library reads it, is what
// the simulator computed: IMU stamps, sequence, covariance and bytes; every
// cloud's stamp (= truth stamp), bytes (regenerated), and for three clouds
// every decoded point, bit for bit.
TEST_P(SimulateRosbagTest, RealRosLibraryReadsEveryMessage) {
  SKIP_WITHOUT_ROSBAG();
  TempDir dir;
  proto::SimulateParams params = ShortScenario();
  params.set_duration_s(2.5);
  params.mutable_bag()->set_compression(GetParam());
  const proto::SimulationTruth truth = Simulate(params, dir, "short");
  Scenario scenario;
  ASSERT_TRUE(BuildScenario(params, &scenario).ok());
  const int last = scenario.num_scans - 1;
  BagDump dump;
  std::string error;
  ASSERT_TRUE(DumpBagWithRosbag(dir.File("short.bag"), dir.File("dump.txt"), {0, 17, last}, &dump,
                                &error))
      << error;
  const char* names[] = {"none", "bz2", "lz4"};
  EXPECT_EQ(dump.compression, names[GetParam()]);

  // IMU.
  const auto& ip = params.imu();
  const auto imu = dump.Topic(ip.topic());
  ASSERT_EQ(static_cast<int>(imu.size()), scenario.num_imu_samples);
  EXPECT_EQ(truth.num_imu_samples(), imu.size());
  const double gyro_var = std::pow(ip.gyro_noise_density_radps_sqrthz(), 2) * ip.rate_hz();
  const double accel_var = std::pow(ip.accel_noise_density_mps2_sqrthz(), 2) * ip.rate_hz();
  for (size_t i = 0; i < imu.size(); ++i) {
    const DumpedMessage& m = *imu[i];
    SCOPED_TRACE("imu " + std::to_string(i));
    const int64_t stamp = params.start_stamp_ns() + std::llround(i * 1e9 / ip.rate_hz());
    ASSERT_EQ(m.type, "sensor_msgs/Imu");
    ASSERT_EQ(m.stamp_ns, stamp);
    ASSERT_EQ(m.record_ns, stamp);
    ASSERT_EQ(m.seq, i);
    ASSERT_EQ(m.frame_id, ip.frame_id());
    ASSERT_NEAR(m.imu[6], gyro_var, 1e-18);
    ASSERT_NEAR(m.imu[7], accel_var, 1e-18);
    ASSERT_EQ(m.imu[8], -1.0);  // no orientation
    // The bytes are our serialization of the values ROS decoded.
    std::string bytes;
    ASSERT_TRUE(ros1::SerializeImu(m.seq, m.stamp_ns, m.frame_id,
                             Eigen::Vector3d(m.imu[0], m.imu[1], m.imu[2]),
                             Eigen::Vector3d(m.imu[3], m.imu[4], m.imu[5]), m.imu[6], m.imu[7],
                             &bytes));
    ASSERT_EQ(m.crc32, Crc32(bytes.data(), bytes.size()));
  }

  // LiDAR.
  const auto& lp = params.lidar();
  const auto clouds = dump.Topic(lp.topic());
  ASSERT_EQ(static_cast<int>(clouds.size()), scenario.num_scans);
  ASSERT_EQ(truth.scans_size(), scenario.num_scans);
  const int64_t tau_ns = std::llround(params.rig().time_offset_s() * 1e9);
  for (int k = 0; k < scenario.num_scans; ++k) {
    const DumpedMessage& m = *clouds[k];
    SCOPED_TRACE("cloud " + std::to_string(k));
    const proto::TruthScan& ts = truth.scans(k);
    ASSERT_EQ(m.type, "sensor_msgs/PointCloud2");
    ASSERT_EQ(m.stamp_ns, ts.stamp_ns());
    ASSERT_EQ(m.record_ns, ts.stamp_ns());
    ASSERT_EQ(ts.true_stamp_ns() - ts.stamp_ns(), tau_ns);
    ASSERT_EQ(m.seq, static_cast<uint32_t>(k));
    ASSERT_EQ(m.frame_id, lp.frame_id());
    ASSERT_EQ(m.height, 1u);
    ASSERT_EQ(m.width, ts.num_points());
    ASSERT_EQ(m.point_step, 23u);
    ASSERT_EQ(m.row_step, 23u * m.width);
    ASSERT_TRUE(m.is_dense);
    ASSERT_FALSE(m.is_bigendian);
    // Driver layout (velodyne_pointcloud XYZIRT) + the label field.
    const std::vector<std::tuple<std::string, uint32_t, uint32_t>> layout = {
        {"x", 0, 7},     {"y", 4, 7},    {"z", 8, 7},     {"intensity", 12, 7},
        {"ring", 16, 4}, {"time", 18, 7}, {"label", 22, 2}};
    ASSERT_EQ(m.fields.size(), layout.size());
    for (size_t f = 0; f < layout.size(); ++f) {
      EXPECT_EQ(m.fields[f].name, std::get<0>(layout[f]));
      EXPECT_EQ(m.fields[f].offset, std::get<1>(layout[f]));
      EXPECT_EQ(m.fields[f].datatype, std::get<2>(layout[f]));
      EXPECT_EQ(m.fields[f].count, 1u);
    }
    // Regenerate the sweep: same bytes.
    const SimulatedScan scan =
        SimulateSweep(scenario.scan, *scenario.trajectory, *scenario.world, params.seed(), k);
    ASSERT_EQ(params.start_stamp_ns() + scan.stamp_true_ns, ts.true_stamp_ns());
    std::string bytes;
    ASSERT_TRUE(SerializeScan(scan, false, true, k, ts.stamp_ns(), lp.frame_id(), &bytes));
    ASSERT_EQ(m.size, bytes.size());
    ASSERT_EQ(m.crc32, Crc32(bytes.data(), bytes.size()));
    if (k == 0 || k == 17 || k == last) {
      ASSERT_EQ(m.points.size(), scan.points.size());
      for (size_t i = 0; i < scan.points.size(); ++i) {
        const ScanPoint& p = scan.points[i];
        const std::vector<double>& q = m.points[i];
        ASSERT_EQ(q.size(), 7u);
        ASSERT_EQ(static_cast<float>(q[0]), p.x) << i;
        ASSERT_EQ(static_cast<float>(q[1]), p.y) << i;
        ASSERT_EQ(static_cast<float>(q[2]), p.z) << i;
        ASSERT_EQ(static_cast<float>(q[3]), p.intensity) << i;
        ASSERT_EQ(q[4], p.ring) << i;
        ASSERT_EQ(static_cast<float>(q[5]), p.time_s) << i;
        ASSERT_EQ(q[6], p.label) << i;
        // End-stamped sweep (driver default): times in [−0.1 s, 0].
        ASSERT_LE(q[5], 0.0);
        ASSERT_GE(q[5], -0.1);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, SimulateRosbagTest,
                         ::testing::Values(proto::SimBagParams::NONE, proto::SimBagParams::BZ2,
                                           proto::SimBagParams::LZ4),
                         [](const auto& info) {
                           return proto::SimBagParams::Compression_Name(info.param);
                         });

// One 4 s run of the short scenario shared by the tests below: bag, truth
// and what the real ROS library reads from it (with the points of a few
// clouds).
struct ShortRun {
  std::unique_ptr<TempDir> dir;
  proto::SimulateParams params;
  proto::SimulationTruth truth;
  BagDump dump;
  std::string error;  // non-empty when the oracle failed
};

class ShortRunTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!NeedRosbag()) return;
    run_ = new ShortRun;
    run_->dir = std::make_unique<TempDir>();
    run_->params = ShortScenario();
    run_->truth = Simulate(run_->params, *run_->dir, "short");
    DumpBagWithRosbag(run_->dir->File("short.bag"), run_->dir->File("dump.txt"), {2, 20, 35},
                      &run_->dump, &run_->error);
  }
  static void TearDownTestSuite() {
    delete run_;
    run_ = nullptr;
  }
  void SetUp() override {
    if (!NeedRosbag()) GTEST_SKIP() << "Debian python3-rosbag (/usr/bin/python3) is not installed";
    ASSERT_TRUE(run_->error.empty()) << run_->error;
  }
  static ShortRun* run_;
};
ShortRun* ShortRunTest::run_ = nullptr;

// Integrating the gyro of the bag (as the ROS library reads it) minus the
// true bias gives the true attitude C_ab at every scan's true time; without
// removing the bias it does not (so the check can fail).
TEST_F(ShortRunTest, GyroIntegrationTracksTheTrueAttitude) {
  const proto::SimulateParams& params = run_->params;
  const proto::SimulationTruth& truth = run_->truth;
  const BagDump& dump = run_->dump;
  const auto imu = dump.Topic(params.imu().topic());
  ASSERT_GT(imu.size(), 100u);
  const Eigen::Vector3d gyro_bias = ToVector(truth.gyro_bias_radps());
  const int64_t t0 = imu[0]->stamp_ns;
  auto omega = [&](size_t i) {
    return Eigen::Vector3d(imu[i]->imu[0], imu[i]->imu[1], imu[i]->imu[2]);
  };
  for (const bool remove_bias : {true, false}) {
    const Eigen::Vector3d bias = remove_bias ? gyro_bias : Eigen::Vector3d::Zero();
    Eigen::Matrix3d c = Eigen::Matrix3d::Identity();  // C_ab(t0) = 1
    size_t i = 0;
    double max_error = 0.0, total_rotation = 0.0;
    for (const proto::TruthScan& ts : truth.scans()) {
      while (i + 1 < imu.size() && imu[i + 1]->stamp_ns <= ts.true_stamp_ns()) {
        const double dt = (imu[i + 1]->stamp_ns - imu[i]->stamp_ns) * 1e-9;
        c = c * Exp((0.5 * (omega(i) + omega(i + 1)) - bias) * dt);
        ++i;
      }
      const double dt = (ts.true_stamp_ns() - imu[i]->stamp_ns) * 1e-9;
      const Eigen::Matrix3d c_at_scan = c * Exp((omega(i) - bias) * dt);
      const Eigen::Matrix3d c_true = ToRotation(ts.world_from_imu());
      max_error = std::max(max_error, AngleBetween(c_true, c_at_scan));
      total_rotation = std::max(total_rotation, AngleBetween(Eigen::Matrix3d::Identity(), c_true));
    }
    EXPECT_GT(total_rotation, 0.5);  // the vehicle turned
    if (remove_bias) {
      EXPECT_LT(max_error, 2e-3) << "rad";
    } else {
      EXPECT_GT(max_error, 5e-3) << "rad";
    }
  }
  // Every sample minus the exact model value and the bias is white noise of
  // the configured level: ω_b(t) and f_b(t) = C_wb^T (r̈_w − g_w) of the
  // scenario's trajectory.
  Scenario scenario;
  ASSERT_TRUE(BuildScenario(params, &scenario).ok());
  const double rate = params.imu().rate_hz();
  const double gyro_sigma = params.imu().gyro_noise_density_radps_sqrthz() * std::sqrt(rate);
  const double accel_sigma = params.imu().accel_noise_density_mps2_sqrthz() * std::sqrt(rate);
  Eigen::Array3d gyro_sum = Eigen::Array3d::Zero(), gyro_sum2 = Eigen::Array3d::Zero();
  Eigen::Array3d accel_sum = Eigen::Array3d::Zero(), accel_sum2 = Eigen::Array3d::Zero();
  for (const DumpedMessage* m : imu) {
    const ImuState state = scenario.trajectory->Evaluate((m->stamp_ns - t0) * 1e-9);
    const Eigen::Vector3d f =
        state.world_from_imu.transpose() * (state.acceleration_w - scenario.gravity_w);
    const Eigen::Array3d eg =
        (Eigen::Vector3d(m->imu[0], m->imu[1], m->imu[2]) - state.angular_velocity_b - gyro_bias)
            .array() / gyro_sigma;
    const Eigen::Array3d ea = (Eigen::Vector3d(m->imu[3], m->imu[4], m->imu[5]) - f -
                               ToVector(truth.accel_bias_mps2()))
                                  .array() / accel_sigma;
    gyro_sum += eg;
    gyro_sum2 += eg * eg;
    accel_sum += ea;
    accel_sum2 += ea * ea;
  }
  const double count = static_cast<double>(imu.size());
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(gyro_sum[axis] / count, 0.0, 5.0 / std::sqrt(count));
    EXPECT_NEAR(accel_sum[axis] / count, 0.0, 5.0 / std::sqrt(count));
    EXPECT_NEAR(std::sqrt(gyro_sum2[axis] / count), 1.0, 0.08);
    EXPECT_NEAR(std::sqrt(accel_sum2[axis] / count), 1.0, 0.08);
  }

  // Static start: the mean specific force is −g_a + b_a (C_ab = 1 at rest).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const DumpedMessage* m : imu) {
    if ((m->stamp_ns - t0) * 1e-9 >= params.trajectory().static_start_s()) break;
    mean += Eigen::Vector3d(m->imu[3], m->imu[4], m->imu[5]);
    ++n;
  }
  ASSERT_GT(n, 50);
  mean /= n;
  const Eigen::Vector3d expected =
      -ToVector(truth.gravity_in_world()) + ToVector(truth.accel_bias_mps2());
  const double sigma = params.imu().accel_noise_density_mps2_sqrthz() *
                       std::sqrt(params.imu().rate_hz()) / std::sqrt(n);
  EXPECT_LT((mean - expected).norm(), 5 * sigma) << mean.transpose();
  EXPECT_NEAR(ToVector(truth.gravity_in_world()).norm(), params.gravity_norm_mps2(), 1e-12);
}

// Points labelled ground, as the ROS library decodes them, lie on the true
// plane of the truth file (n_l · p + d_l = 0) within the range noise
// projected on the normal, σ |d̂ · n_l| (d̂ = the ray direction).
TEST_F(ShortRunTest, GroundPointsFitTheTruePlane) {
  const proto::SimulateParams& params = run_->params;
  const proto::SimulationTruth& truth = run_->truth;
  const BagDump& dump = run_->dump;
  const std::vector<int> dumped = {2, 20, 35};
  const auto clouds = dump.Topic(params.lidar().topic());
  const double sigma = params.lidar().range_noise_m();
  for (int k : dumped) {
    SCOPED_TRACE("scan " + std::to_string(k));
    const proto::TruthScan& ts = truth.scans(k);
    const Eigen::Vector3d n = ToVector(ts.ground_normal_in_lidar());
    EXPECT_NEAR(n.norm(), 1.0, 1e-12);
    const double d = ts.ground_height_m();
    double sum_normalized = 0.0, max_abs = 0.0;
    int ground = 0, off_plane_non_ground = 0, non_ground = 0;
    for (const std::vector<double>& q : clouds[k]->points) {
      const Eigen::Vector3d p(q[0], q[1], q[2]);
      const double residual = n.dot(p) + d;
      if (q[6] == 1) {  // SURFACE_GROUND
        ++ground;
        const double projected = sigma * std::abs(p.normalized().dot(n));
        sum_normalized += std::pow(residual / projected, 2);
        max_abs = std::max(max_abs, std::abs(residual));
      } else {
        ++non_ground;
        off_plane_non_ground += std::abs(residual) > 5 * sigma;
      }
    }
    EXPECT_EQ(static_cast<uint32_t>(ground), ts.num_ground_points());
    ASSERT_GT(ground, 1000);
    const double rms_normalized = std::sqrt(sum_normalized / ground);
    EXPECT_GT(rms_normalized, 0.85);  // the noise is there
    EXPECT_LT(rms_normalized, 1.15);  // and nothing else
    EXPECT_LT(max_abs, 5 * sigma);
    // Walls, boxes and pillars are mostly off the plane.
    EXPECT_GT(off_plane_non_ground, 0.8 * non_ground);
    // The truth plane is consistent with the rig: d_l = d_b + n_l · C_bl^T r_b^{lb}.
    const Eigen::Matrix3d c_bl = ToRotation(truth.imu_from_lidar());
    const Eigen::Vector3d r_bl = ToVector(truth.imu_from_lidar().translation());
    EXPECT_NEAR(d, truth.imu_height_m() + n.dot(c_bl.transpose() * r_bl), 1e-9);
    EXPECT_NEAR(ts.inclination_deg(),
                geometry::RadToDeg(std::acos(std::cos(geometry::DegToRad(3)) *
                                             std::cos(geometry::DegToRad(8)))),
                1e-9);
  }
}

// Each point, taken at its own time (stamp + time field + τ, IMU clock) with
// the true LiDAR pose of that time, lands on the surface it hit: wall points
// on |x| = h or |y| = h. This checks the per-point times, the stamp
// convention (end of sweep) and the sign of τ: with t − τ instead, or without
// the per-point times, the points miss the walls.
TEST_F(ShortRunTest, PointsLandOnTheWallsAtTheirTrueTimes) {
  const proto::SimulateParams& params = run_->params;
  const proto::SimulationTruth& truth = run_->truth;
  const BagDump& dump = run_->dump;
  Scenario scenario;
  ASSERT_TRUE(BuildScenario(params, &scenario).ok());
  const std::vector<int> dumped = {20, 35};
  const auto clouds = dump.Topic(params.lidar().topic());
  const double half = params.world().room_half_size_m();
  const double sigma = params.lidar().range_noise_m();
  const Eigen::Matrix3d c_bl = ToRotation(truth.imu_from_lidar());
  const Eigen::Vector3d r_bl = ToVector(truth.imu_from_lidar().translation());
  const double tau = truth.time_offset_s();
  // RMS distance of the wall points to the room walls, with point times
  // stamp + time_scale * time + tau_sign * τ.
  auto wall_rms = [&](const DumpedMessage& m, double time_scale, double tau_sign) {
    double sum = 0.0;
    int n = 0;
    for (const std::vector<double>& q : m.points) {
      if (q[6] != 2) continue;  // SURFACE_WALL
      const double t = (m.stamp_ns - params.start_stamp_ns()) * 1e-9 + time_scale * q[5] +
                       tau_sign * tau;
      Eigen::Matrix3d c_wb;
      Eigen::Vector3d r_wb;
      scenario.trajectory->Pose(t, &c_wb, &r_wb);
      const Eigen::Vector3d p = c_wb * (c_bl * Eigen::Vector3d(q[0], q[1], q[2]) + r_bl) + r_wb;
      const double d = std::min(std::abs(half - std::abs(p.x())), std::abs(half - std::abs(p.y())));
      sum += d * d;
      ++n;
    }
    EXPECT_GT(n, 500);
    return std::sqrt(sum / n);
  };
  for (int k : dumped) {
    SCOPED_TRACE("scan " + std::to_string(k));
    const double rms = wall_rms(*clouds[k], 1.0, 1.0);
    EXPECT_LT(rms, 1.2 * sigma);
    EXPECT_GT(rms, 0.3 * sigma);
    EXPECT_GT(wall_rms(*clouds[k], 1.0, -1.0), 3 * rms);  // τ with the wrong sign
    EXPECT_GT(wall_rms(*clouds[k], 0.0, 1.0), 3 * rms);   // no per-point times
  }
}

TEST(SimulateTest, SameSeedSameBytesOtherSeedOtherBytes) {
  TempDir dir;
  proto::SimulateParams params = ShortScenario();
  params.set_duration_s(1.5);
  params.mutable_bag()->set_compression(proto::SimBagParams::LZ4);
  params.set_num_threads(1);
  const proto::SimulationTruth a = Simulate(params, dir, "a");
  params.set_num_threads(3);
  const proto::SimulationTruth b = Simulate(params, dir, "b");
  params.set_seed(params.seed() + 1);
  Simulate(params, dir, "c");
  std::string bag_a, bag_b, bag_c;
  ASSERT_TRUE(ReadFileToString(dir.File("a.bag"), &bag_a).ok());
  ASSERT_TRUE(ReadFileToString(dir.File("b.bag"), &bag_b).ok());
  ASSERT_TRUE(ReadFileToString(dir.File("c.bag"), &bag_c).ok());
  EXPECT_GT(bag_a.size(), 100000u);
  EXPECT_TRUE(bag_a == bag_b);
  EXPECT_FALSE(bag_a == bag_c);
  proto::SimulationTruth a2 = a, b2 = b;
  a2.clear_provenance();
  b2.clear_provenance();
  EXPECT_EQ(a2.SerializeAsString(), b2.SerializeAsString());
}

TEST(SimulateTest, RigFileHoldsThePerturbedExtrinsic) {
  TempDir dir;
  proto::SimulateParams params = ShortScenario();
  params.set_duration_s(0.5);
  const proto::SimulationTruth truth = Simulate(params, dir, "r");
  proto::Rig rig;
  ASSERT_TRUE(ReadTextProto(dir.File("r_rig.txtpb"), &rig).ok());
  const Eigen::Vector3d dt = ToVector(rig.imu_from_lidar().translation()) -
                             ToVector(truth.imu_from_lidar().translation());
  EXPECT_TRUE(dt.isApprox(ToVector(params.rig_file().translation_error_m()), 1e-12));
  const double angle =
      AngleBetween(ToRotation(rig.imu_from_lidar()), ToRotation(truth.imu_from_lidar()));
  const Eigen::Vector3d e = geometry::DegToRad(ToVector(params.rig_file().rotation_error_deg()));
  EXPECT_NEAR(angle, e.norm(), 0.01 * e.norm());  // small angles: |Euler| ≈ angle
  EXPECT_EQ(rig.imu_height_m(), truth.imu_height_m());
  EXPECT_EQ(rig.imu_topic(), params.imu().topic());
  EXPECT_EQ(rig.lidar_topic(), params.lidar().topic());
  EXPECT_EQ(rig.lidar_model(), "VLP-16");
  EXPECT_TRUE(ToVector(rig.gravity_flat_in_imu()).isApprox(ToVector(truth.gravity_flat_in_imu())));
  // g_f of the upside-down IMU points along its +z.
  EXPECT_NEAR(truth.gravity_flat_in_imu().z(), params.gravity_norm_mps2(), 1e-12);
}

TEST(SimulateTest, BadParamsAreAClearErrorAndLeaveNoOutput) {
  TempDir dir;
  proto::SimulateParams params = ShortScenario();
  params.mutable_lidar()->set_max_range_m(0.4);
  SimulatePaths paths;
  paths.out_bag = dir.File("x.bag");
  paths.out_truth = dir.File("x.txtpb");
  Status status = simulate::Run(paths, params, nullptr);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("max_range_m"), std::string::npos) << status.message();
  params = ShortScenario();
  params.mutable_world()->set_room_half_size_m(5);
  status = simulate::Run(paths, params, nullptr);
  EXPECT_NE(status.message().find("room_half_size_m"), std::string::npos) << status.message();
  params = ShortScenario();
  params.mutable_rig()->set_imu_height_m(0.1);  // the LiDAR would be under the ground
  params.mutable_rig()->mutable_lidar_translation_in_imu_m()->set_z(0.4);
  status = simulate::Run(paths, params, nullptr);
  EXPECT_NE(status.message().find("above the ground"), std::string::npos) << status.message();
  EXPECT_FALSE(tiltcal::testing::FileExists(paths.out_bag));
  EXPECT_FALSE(tiltcal::testing::FileExists(paths.out_truth));
  // The command line reports the schema error with the field name, exit 1.
  const std::string tool = tiltcal::testing::ToolPath("tiltcal_simulate");
  if (tiltcal::testing::FileExists(tool)) {
    ASSERT_TRUE(WriteFileAtomically(dir.File("bad.txtpb"), "seed: 1\nduration_s: -3\n").ok());
    std::string output;
    EXPECT_EQ(tiltcal::testing::RunCommand(tool + " --params=" + dir.File("bad.txtpb") +
                                               " --out_bag=" + paths.out_bag +
                                               " --out_truth=" + paths.out_truth,
                                           &output),
              1);
    EXPECT_NE(output.find("duration_s"), std::string::npos) << output;
    EXPECT_FALSE(tiltcal::testing::FileExists(paths.out_bag));
  }
}

// The scenarios of the repository (demo and tests) pass the schema and the
// simulator's own checks.
TEST(SimulateTest, RepositoryScenariosAreValid) {
  for (const char* name : {"flat_vlp16", "flat_vlp16_40s", "tilted_husky_vlp16",
                           "flat_m2dgr_vlp32c", "offroad_os1_32", "short_test_vlp16"}) {
    SCOPED_TRACE(name);
    proto::SimulateParams params;
    const Status loaded = LoadParams(tiltcal::testing::SourceDir() + "/stages/simulate/scenarios/" +
                                         name + ".txtpb",
                                     &params);
    ASSERT_TRUE(loaded.ok()) << loaded.message();
    Scenario scenario;
    const Status built = BuildScenario(params, &scenario);
    ASSERT_TRUE(built.ok()) << built.message();
    EXPECT_GT(scenario.num_scans, 0);
    EXPECT_GT(scenario.world->boxes().size() + scenario.world->pillars().size(), 10u);
  }
}

TEST(SimulateTest, CommandLineWritesAllOutputs) {
  const std::string tool = tiltcal::testing::ToolPath("tiltcal_simulate");
  if (!tiltcal::testing::FileExists(tool)) GTEST_SKIP() << "build the tiltcal_simulate target";
  TempDir dir;
  proto::SimulateParams params = ShortScenario();
  params.set_duration_s(0.5);
  ASSERT_TRUE(WriteTextProto(dir.File("s.txtpb"), params).ok());
  std::string output;
  ASSERT_EQ(tiltcal::testing::RunCommand(tool + " --params=" + dir.File("s.txtpb") +
                                             " --out_bag=" + dir.File("s.bag") +
                                             " --out_truth=" + dir.File("t.txtpb") +
                                             " --out_rig=" + dir.File("r.txtpb"),
                                         &output),
            0)
      << output;
  proto::SimulationTruth truth;
  ASSERT_TRUE(ReadTextProto(dir.File("t.txtpb"), &truth).ok());
  EXPECT_EQ(truth.provenance().producer(), "tiltcal_simulate");
  EXPECT_NE(truth.provenance().params_txtpb().find("duration_s: 0.5"), std::string::npos);
  EXPECT_EQ(truth.scans_size(), 4);  // sweeps at 0.05 + k/10 s ending before 0.5 s
  EXPECT_TRUE(tiltcal::testing::FileExists(dir.File("s.bag")));
  EXPECT_TRUE(tiltcal::testing::FileExists(dir.File("r.txtpb")));
  EXPECT_NE(output.find("4 scans"), std::string::npos) << output;
}

// OS1-32 (organized, `t` uint32 ns from the first column) and VLP-32C, as
// the ROS library reads them.
TEST(SimulateTest, OusterAndVlp32cLayouts) {
  SKIP_WITHOUT_ROSBAG();
  TempDir dir;
  for (const auto model : {proto::SimLidarParams::OS1_32, proto::SimLidarParams::VLP_32C}) {
    proto::SimulateParams params = ShortScenario();
    params.set_duration_s(0.6);
    params.mutable_lidar()->set_model(model);
    params.mutable_lidar()->set_ouster_columns(512);
    params.mutable_lidar()->set_velodyne_stamp_at_start(true);
    params.mutable_bag()->set_compression(proto::SimBagParams::LZ4);
    const proto::SimulationTruth truth = Simulate(params, dir, "m");
    BagDump dump;
    std::string error;
    ASSERT_TRUE(DumpBagWithRosbag(dir.File("m.bag"), dir.File("m.txt"), {1}, &dump, &error))
        << error;
    const auto clouds = dump.Topic(params.lidar().topic());
    ASSERT_EQ(clouds.size(), static_cast<size_t>(truth.scans_size()));
    ASSERT_GE(clouds.size(), 2u);
    const DumpedMessage& m = *clouds[1];
    EXPECT_EQ(m.stamp_ns, truth.scans(1).stamp_ns());
    std::vector<std::string> names;
    for (const auto& f : m.fields) names.push_back(f.name);
    int valid = 0;
    if (model == proto::SimLidarParams::OS1_32) {
      EXPECT_EQ(m.height, 32u);
      EXPECT_EQ(m.width, 512u);
      EXPECT_EQ(m.point_step, 48u);
      EXPECT_FALSE(m.is_dense);
      EXPECT_EQ(names, (std::vector<std::string>{"x", "y", "z", "intensity", "t", "reflectivity",
                                                 "ring", "ambient", "range", "label"}));
      EXPECT_EQ(m.fields[4].datatype, 6u);  // t UINT32
      ASSERT_EQ(m.points.size(), 32u * 512u);
      for (size_t i = 0; i < m.points.size(); ++i) {
        // read_points orders values by field offset:
        // x y z intensity t reflectivity ring ambient label(@30) range(@32).
        const auto& q = m.points[i];
        EXPECT_EQ(q[6], static_cast<double>(i / 512));  // row = ring
        EXPECT_EQ(q[4], std::llround((i % 512) * 1e9 / (10.0 * 512)));  // column time, ns
        if (std::isnan(q[0])) {
          EXPECT_EQ(q[9], 0.0);
          EXPECT_EQ(q[8], 0.0);  // SURFACE_NONE
        } else {
          ++valid;
          EXPECT_NEAR(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]), q[9] * 1e-3, 1e-3);
          EXPECT_GE(q[8], 1.0);
        }
      }
    } else {
      EXPECT_EQ(m.height, 1u);
      EXPECT_EQ(m.point_step, 23u);
      double lo = 1, hi = -1, max_ring = 0;
      for (const auto& q : m.points) {
        lo = std::min(lo, q[5]);
        hi = std::max(hi, q[5]);
        max_ring = std::max(max_ring, q[4]);
        ++valid;
      }
      EXPECT_GE(lo, 0.0);  // start-stamped
      EXPECT_LT(hi, 0.1);
      EXPECT_GT(hi, 0.09);
      EXPECT_EQ(max_ring, 31);
    }
    EXPECT_EQ(static_cast<uint32_t>(valid), truth.scans(1).num_points());
  }
}

// The C++ rosbag library of ros_comm (Debian librosbag-storage-dev, with the
// strict roslz4 decoder) reads the bags too: the decode benchmark's anchor
// reader, when built (cmake --build BUILD --target tiltcal_bench_rosbag_cpp_reader).
TEST(SimulateTest, CppRosbagLibraryReadsTheBags) {
  const std::string reader = tiltcal::testing::ToolPath("tiltcal_bench_rosbag_cpp_reader");
  if (!tiltcal::testing::FileExists(reader)) {
    GTEST_SKIP() << "build the tiltcal_bench_rosbag_cpp_reader target to run this test";
  }
  for (const auto compression : {proto::SimBagParams::NONE, proto::SimBagParams::BZ2,
                                 proto::SimBagParams::LZ4}) {
    SCOPED_TRACE(proto::SimBagParams::Compression_Name(compression));
    TempDir dir;
    proto::SimulateParams params = ShortScenario();
    params.set_duration_s(1.0);
    params.mutable_bag()->set_compression(compression);
    const proto::SimulationTruth truth = Simulate(params, dir, "cpp");
    uint64_t points = 0;
    for (const auto& scan : truth.scans()) points += scan.num_points();
    std::string output;
    ASSERT_EQ(tiltcal::testing::RunCommand(reader + " " + dir.File("cpp.bag"), &output), 0)
        << output;
    EXPECT_NE(output.find("messages=" + std::to_string(truth.num_imu_samples() +
                                                       truth.scans_size()) + " "),
              std::string::npos) << output;
    EXPECT_NE(output.find("clouds=" + std::to_string(truth.scans_size()) + " "),
              std::string::npos) << output;
    EXPECT_NE(output.find("points=" + std::to_string(points) + " "), std::string::npos) << output;
    EXPECT_NE(output.find("imu=" + std::to_string(truth.num_imu_samples()) + " "),
              std::string::npos) << output;
  }
}

// tiltcal_decode reads the simulated bags back: same counts, stamps and
// points per scan as the truth.
TEST(SimulateTest, DecodeReadsTheBagBack) {
  const std::string decode = tiltcal::testing::ToolPath("tiltcal_decode");
  const std::string decode_params =
      tiltcal::testing::SourceDir() + "/stages/decode/default_params.txtpb";
  if (!tiltcal::testing::FileExists(decode) || !tiltcal::testing::FileExists(decode_params)) {
    GTEST_SKIP() << "build the tiltcal_decode target to run this test";
  }
  for (const auto compression : {proto::SimBagParams::NONE, proto::SimBagParams::BZ2,
                                 proto::SimBagParams::LZ4}) {
    SCOPED_TRACE(proto::SimBagParams::Compression_Name(compression));
    TempDir dir;
    proto::SimulateParams params = ShortScenario();
    params.set_duration_s(2.0);
    params.mutable_bag()->set_compression(compression);
    const proto::SimulationTruth truth = Simulate(params, dir, "d");
    std::string output;
    ASSERT_EQ(tiltcal::testing::RunCommand(decode + " --bag=" + dir.File("d.bag") +
                                               " --params=" + decode_params +
                                               " --out_imu=" + dir.File("imu.binpb") +
                                               " --out_scans=" + dir.File("scans.binpb.lz4"),
                                           &output),
              0)
        << output;
    std::vector<proto::ImuSample> imu;
    std::vector<proto::Scan> scans;
    Status status = ReadAllRecords<proto::ImuSample>(dir.File("imu.binpb"), &imu);
    ASSERT_TRUE(status.ok()) << status.message();
    status = ReadAllRecords<proto::Scan>(dir.File("scans.binpb.lz4"), &scans);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_EQ(imu.size(), truth.num_imu_samples());
    for (size_t i = 0; i < imu.size(); ++i) {
      ASSERT_EQ(imu[i].stamp_ns(),
                params.start_stamp_ns() + std::llround(i * 1e9 / params.imu().rate_hz()));
    }
    ASSERT_EQ(scans.size(), static_cast<size_t>(truth.scans_size()));
    for (size_t k = 0; k < scans.size(); ++k) {
      const proto::TruthScan& ts = truth.scans(static_cast<int>(k));
      EXPECT_EQ(scans[k].stamp_ns(), ts.stamp_ns());
      EXPECT_NEAR(scans[k].x_size(), static_cast<int>(ts.num_points()), 2);
      ASSERT_EQ(scans[k].time_offset_ns_size(), scans[k].x_size());
      int min_offset = 0, max_offset = -1000000000;
      for (int t : scans[k].time_offset_ns()) {
        min_offset = std::min(min_offset, t);
        max_offset = std::max(max_offset, t);
      }
      EXPECT_LE(max_offset, 0);  // end-stamped Velodyne
      EXPECT_GT(min_offset, -100000000);
      EXPECT_LT(min_offset, -99000000);
    }
  }
}

}  // namespace
}  // namespace tiltcal::simulate
