// Deskewing: a LiDAR turning during the sweep, IMU readings generated from the
// same motion through the rig extrinsic; the deskewed plane must match the
// truth at the stamp, the raw one must not.
#include "stages/ground/deskew.h"

#include "common/geometry/angles.h"
#include "common/imu/gyro_integrator.h"
#include "common/imu/imu_reading.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "stages/ground/scan_processor.h"
#include "tests/stages/ground/ground_test_util.h"
#include "tests/testing/synthetic_lidar.h"

namespace tiltcal::ground {
namespace {

using geometry::AngleBetweenDeg;
using testing::CastScan;
using testing::DefaultGroundParams;
using testing::GroundParamsWith;
using testing::NormalOf;
using testing::RollPitchYaw;
using testing::StreetScene;
using testing::SyntheticLidar;
using testing::SyntheticPose;

constexpr int64_t kStampNs = 5000000000LL;

// IMU readings at 400 Hz over [t0, t1] (IMU clock, ns; times in the readings
// are seconds from t0) with a constant body rate and a constant gyro bias.
std::vector<imu::ImuReading> ConstantRateImu(int64_t t0_ns, int64_t t1_ns,
                                             const Eigen::Vector3d& omega_b,
                                             const Eigen::Vector3d& bias) {
  std::vector<imu::ImuReading> samples;
  for (int64_t t = t0_ns; t <= t1_ns; t += 2500000) {
    imu::ImuReading s;
    s.time_s = 1e-9 * static_cast<double>(t - t0_ns);
    s.angular_velocity_radps = omega_b + bias;
    s.linear_acceleration_mps2 = Eigen::Vector3d(0, 0, 9.81);
    samples.push_back(s);
  }
  return samples;
}

struct DeskewCase {
  proto::Scan scan;
  SyntheticPose pose;
  Eigen::Matrix3d c_bl;
  std::vector<imu::ImuReading> imu;
  int64_t imu_origin_ns;
  int64_t tau_ns;
};

DeskewCase MakeCase() {
  DeskewCase c;
  c.c_bl = RollPitchYaw(0.02, -0.03, M_PI / 2);  // LiDAR yawed 90 deg on the IMU
  c.pose.position_g = Eigen::Vector3d(0, 0, 0.9);
  c.pose.g_from_lidar = RollPitchYaw(0.03, 0.05, 0.2);
  c.pose.omega_lidar_radps = Eigen::Vector3d(0.8, -0.6, 1.2);  // fast rocking + turning
  c.scan = CastScan(StreetScene(11), SyntheticLidar::Vlp16(), c.pose, kStampNs, 11);
  c.tau_ns = 7000000;  // IMU clock = LiDAR clock + 7 ms (deskew.time_offset_s below)
  const Eigen::Vector3d omega_b = c.c_bl * c.pose.omega_lidar_radps;
  c.imu_origin_ns = kStampNs + c.tau_ns - 1000000000LL;
  c.imu = ConstantRateImu(c.imu_origin_ns, kStampNs + c.tau_ns + 1000000000LL, omega_b,
                          Eigen::Vector3d::Zero());
  return c;
}

// The defaults with τ = 7 ms, as in MakeCase.
proto::GroundParams ParamsOfTheCase() {
  return GroundParamsWith("deskew { time_offset_s: 0.007 }");
}

TEST(Deskewer, DeskewedPlaneMatchesTheTruthAtTheStamp) {
  DeskewCase c = MakeCase();
  const proto::GroundParams params = ParamsOfTheCase();
  // Raw (skewed) scan.
  ScanProcessor raw(params, GroundFrame(), nullptr);
  proto::Scan raw_scan = c.scan;
  const proto::GroundPlane raw_plane = raw.Process(&raw_scan);
  // Deskewed.
  imu::GyroIntegrator integrator(c.imu, Eigen::Vector3d::Zero());
  Deskewer deskewer(&integrator, c.imu_origin_ns, c.c_bl, params.deskew());
  ScanProcessor processor(params, GroundFrame(), &deskewer);
  proto::Scan scan = c.scan;
  const proto::GroundPlane plane = processor.Process(&scan);
  ASSERT_TRUE(plane.valid()) << plane.reject_detail();
  EXPECT_TRUE(plane.deskewed());
  EXPECT_TRUE(scan.deskewed());
  const double err = AngleBetweenDeg(NormalOf(plane), testing::TrueNormal(c.pose));
  const double raw_err = AngleBetweenDeg(NormalOf(raw_plane), testing::TrueNormal(c.pose));
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
  imu::GyroIntegrator integrator(c.imu, Eigen::Vector3d::Zero());
  // 1 ms rotation nodes: the bound below depends on them.
  const proto::GroundParams params =
      GroundParamsWith("deskew { time_offset_s: 0.007 node_spacing_s: 0.001 }");
  Deskewer deskewer(&integrator, c.imu_origin_ns, c.c_bl, params.deskew());
  proto::Scan scan = c.scan;
  ASSERT_TRUE(deskewer.Deskew(scan.stamp_ns(), scan.time_offset_ns().data(),
                              static_cast<size_t>(scan.x_size()), scan.mutable_x()->mutable_data(),
                              scan.mutable_y()->mutable_data(), scan.mutable_z()->mutable_data()));
  double worst = 0.0;
  for (int i = 0; i < scan.x_size(); ++i) {
    const double dt = 1e-9 * scan.time_offset_ns(i);
    const Eigen::Vector3d omega = c.pose.omega_lidar_radps;
    const Eigen::Matrix3d r_t =
        c.pose.g_from_lidar *
        Eigen::AngleAxisd(omega.norm() * dt, omega.normalized()).toRotationMatrix();
    const Eigen::Vector3d raw(c.scan.x(i), c.scan.y(i), c.scan.z(i));
    const Eigen::Vector3d expected = still.g_from_lidar.transpose() * r_t * raw;
    const Eigen::Vector3d got(scan.x(i), scan.y(i), scan.z(i));
    worst = std::max(worst, (got - expected).norm() / std::max(1.0, raw.norm()));
  }
  EXPECT_LT(worst, 2e-6);  // float precision relative to range
}

TEST(Deskewer, NoImuCoverageIsARejectionNotANan) {
  DeskewCase c = MakeCase();
  // The readings start 25 ms after the stamp.
  std::vector<imu::ImuReading> late(c.imu.begin() + 410, c.imu.end());
  imu::GyroIntegrator integrator(late, Eigen::Vector3d::Zero());
  const proto::GroundParams params = ParamsOfTheCase();
  Deskewer deskewer(&integrator, c.imu_origin_ns, c.c_bl, params.deskew());
  ScanProcessor processor(params, GroundFrame(), &deskewer);
  proto::Scan scan = c.scan;
  const proto::GroundPlane plane = processor.Process(&scan);
  EXPECT_FALSE(plane.valid());
  EXPECT_EQ(plane.reject_reason(), proto::GROUND_NO_IMU_COVERAGE);
  EXPECT_TRUE(testing::NoNan(plane));
  EXPECT_FALSE(scan.deskewed());
}

}  // namespace
}  // namespace tiltcal::ground
