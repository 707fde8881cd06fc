// Deskewing: a LiDAR turning during the sweep, IMU readings generated from the
// same motion through the rig extrinsic; the deskewed plane must match the
// truth at the stamp, the raw one must not.
#include "stages/ground/deskew.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "stages/ground/scan_processor.h"
#include "tests/stages/ground/ground_test_util.h"
#include "tests/stages/ground/synthetic_lidar.h"

namespace tiltcal::ground {
namespace {

using testing::AngleDeg;
using testing::CastScan;
using testing::DefaultGroundParams;
using testing::NormalOf;
using testing::RollPitchYaw;
using testing::StreetScene;
using testing::SyntheticLidar;
using testing::SyntheticPose;

constexpr int64_t kStampNs = 5000000000LL;

// IMU samples at 400 Hz over [t0, t1] (IMU clock) with a constant body rate
// and a constant gyro bias.
std::vector<proto::ImuSample> ConstantRateImu(int64_t t0_ns, int64_t t1_ns,
                                              const Eigen::Vector3d& omega_b,
                                              const Eigen::Vector3d& bias) {
  std::vector<proto::ImuSample> samples;
  for (int64_t t = t0_ns; t <= t1_ns; t += 2500000) {
    proto::ImuSample s;
    s.set_stamp_ns(t);
    s.mutable_angular_velocity_radps()->set_x(omega_b.x() + bias.x());
    s.mutable_angular_velocity_radps()->set_y(omega_b.y() + bias.y());
    s.mutable_angular_velocity_radps()->set_z(omega_b.z() + bias.z());
    s.mutable_linear_acceleration_mps2()->set_z(9.81);
    samples.push_back(s);
  }
  return samples;
}

TEST(GyroIntegrator, ConstantRateGivesTheExactRotation) {
  const Eigen::Vector3d w(0.3, -0.2, 0.5), bias(0.01, 0.02, -0.03);
  const auto samples = ConstantRateImu(0, 2000000000LL, w, bias);
  GyroIntegrator integrator(samples, bias);
  const Eigen::Quaterniond q = integrator.Orientation(1234567890LL);
  const Eigen::Quaterniond expected(Eigen::AngleAxisd(w.norm() * 1.23456789, w.normalized()));
  EXPECT_LT(q.angularDistance(expected), 1e-9);
  EXPECT_TRUE(integrator.Covers(0, 2000000000LL));
  EXPECT_FALSE(integrator.Covers(-1, 10));
}

TEST(StaticStart, BiasIsTheMeanOfTheStillPrefix) {
  const Eigen::Vector3d bias(0.004, -0.006, 0.002);
  auto samples = ConstantRateImu(0, 1000000000LL, Eigen::Vector3d::Zero(), bias);
  const auto moving = ConstantRateImu(1002500000LL, 3000000000LL, Eigen::Vector3d(0, 0, 0.8), bias);
  samples.insert(samples.end(), moving.begin(), moving.end());
  const StaticStart s = EstimateStaticGyroBias(samples, 0.05, 0.5);
  ASSERT_TRUE(s.found);
  EXPECT_NEAR(s.duration_s, 1.0, 1e-6);
  EXPECT_LT((s.gyro_bias_radps - bias).norm(), 1e-12);
  EXPECT_FALSE(EstimateStaticGyroBias(moving, 0.05, 0.5).found);
}

struct DeskewCase {
  proto::Scan scan;
  SyntheticPose pose;
  Eigen::Matrix3d c_bl;
  std::vector<proto::ImuSample> imu;
  int64_t tau_ns;
};

DeskewCase MakeCase() {
  DeskewCase c;
  c.c_bl = RollPitchYaw(0.02, -0.03, M_PI / 2);  // LiDAR yawed 90 deg on the IMU
  c.pose.position_g = Eigen::Vector3d(0, 0, 0.9);
  c.pose.g_from_lidar = RollPitchYaw(0.03, 0.05, 0.2);
  c.pose.omega_lidar_radps = Eigen::Vector3d(0.8, -0.6, 1.2);  // fast rocking + turning
  c.scan = CastScan(StreetScene(11), SyntheticLidar::Vlp16(), c.pose, kStampNs, 11);
  c.tau_ns = 7000000;  // IMU clock = LiDAR clock + 7 ms
  const Eigen::Vector3d omega_b = c.c_bl * c.pose.omega_lidar_radps;
  c.imu = ConstantRateImu(kStampNs + c.tau_ns - 1000000000LL, kStampNs + c.tau_ns + 1000000000LL,
                          omega_b, Eigen::Vector3d::Zero());
  return c;
}

TEST(Deskewer, DeskewedPlaneMatchesTheTruthAtTheStamp) {
  DeskewCase c = MakeCase();
  const proto::GroundParams params = DefaultGroundParams();
  // Raw (skewed) scan.
  ScanProcessor raw(params, GroundFrame(), nullptr);
  proto::Scan raw_scan = c.scan;
  const proto::GroundPlane raw_plane = raw.Process(&raw_scan);
  // Deskewed.
  GyroIntegrator integrator(c.imu, Eigen::Vector3d::Zero());
  Deskewer deskewer(&integrator, c.c_bl, c.tau_ns, params.deskew_node_spacing_s());
  ScanProcessor processor(params, GroundFrame(), &deskewer);
  proto::Scan scan = c.scan;
  const proto::GroundPlane plane = processor.Process(&scan);
  ASSERT_TRUE(plane.valid()) << plane.reject_detail();
  EXPECT_TRUE(plane.deskewed());
  EXPECT_TRUE(scan.deskewed());
  const double err = AngleDeg(NormalOf(plane), testing::TrueNormal(c.pose));
  const double raw_err = AngleDeg(NormalOf(raw_plane), testing::TrueNormal(c.pose));
  std::printf("normal error deskewed %.4f deg, raw %.4f deg\n", err, raw_err);
  EXPECT_LT(err, 0.1);
  EXPECT_GT(raw_err, 3.0 * err);
  EXPECT_NEAR(plane.height_m(), 0.9, 0.005);
}

TEST(Deskewer, PointsMatchTheFrameAtTheStamp) {
  // Noise-free: every deskewed point must equal the hit point expressed in
  // the LiDAR frame at the stamp (the oracle is the ray-cast geometry).
  DeskewCase c = MakeCase();
  SyntheticLidar lidar = SyntheticLidar::Vlp16();
  lidar.range_noise_m = 0.0;
  lidar.azimuth_steps = 360;
  SyntheticPose still = c.pose;
  c.scan = CastScan(StreetScene(11), lidar, c.pose, kStampNs, 1);
  GyroIntegrator integrator(c.imu, Eigen::Vector3d::Zero());
  Deskewer deskewer(&integrator, c.c_bl, c.tau_ns, 0.001);
  proto::Scan scan = c.scan;
  ASSERT_TRUE(deskewer.Deskew(scan.stamp_ns(), scan.time_offset_ns().data(),
                              static_cast<size_t>(scan.x_size()), scan.mutable_x()->mutable_data(),
                              scan.mutable_y()->mutable_data(), scan.mutable_z()->mutable_data()));
  double worst = 0.0;
  for (int i = 0; i < scan.x_size(); ++i) {
    const double dt = 1e-9 * scan.time_offset_ns(i);
    const Eigen::Matrix3d r_t =
        c.pose.g_from_lidar *
        Eigen::AngleAxisd(c.pose.omega_lidar_radps.norm() * dt, c.pose.omega_lidar_radps.normalized())
            .toRotationMatrix();
    const Eigen::Vector3d raw(c.scan.x(i), c.scan.y(i), c.scan.z(i));
    const Eigen::Vector3d expected = still.g_from_lidar.transpose() * r_t * raw;
    const Eigen::Vector3d got(scan.x(i), scan.y(i), scan.z(i));
    worst = std::max(worst, (got - expected).norm() / std::max(1.0, raw.norm()));
  }
  EXPECT_LT(worst, 2e-6);  // float precision relative to range
}

TEST(Deskewer, NoImuCoverageIsARejectionNotANan) {
  DeskewCase c = MakeCase();
  std::vector<proto::ImuSample> late(c.imu.begin() + 410, c.imu.end());  // starts after the stamp
  GyroIntegrator integrator(late, Eigen::Vector3d::Zero());
  Deskewer deskewer(&integrator, c.c_bl, c.tau_ns, 0.001);
  ScanProcessor processor(DefaultGroundParams(), GroundFrame(), &deskewer);
  proto::Scan scan = c.scan;
  const proto::GroundPlane plane = processor.Process(&scan);
  EXPECT_FALSE(plane.valid());
  EXPECT_EQ(plane.reject_reason(), proto::GROUND_NO_IMU_COVERAGE);
  EXPECT_TRUE(testing::NoNan(plane));
  EXPECT_FALSE(scan.deskewed());
}

}  // namespace
}  // namespace tiltcal::ground
