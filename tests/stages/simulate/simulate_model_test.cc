// Math of the simulator: Euler convention, trajectory derivatives against
// finite differences, planar-motion invariants, ray casting against a brute
// force ray march, LiDAR firing patterns, random streams.
#include <cmath>
#include <set>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "stages/simulate/lidar_model.h"
#include "stages/simulate/random.h"
#include "stages/simulate/scan_simulator.h"
#include "stages/simulate/trajectory.h"
#include "stages/simulate/world.h"

namespace tiltcal::simulate {
namespace {

using geometry::kRadPerDeg;

TEST(SimEulerAnglesTest, HuskyRigHasTheImuUpsideDownRelativeToTheLidar) {
  const Eigen::Matrix3d c_bl = geometry::RotationFromEuler123Deg(Eigen::Vector3d(180, 0, -90));
  EXPECT_TRUE((c_bl * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
  // Yaw −90 applied last: the LiDAR x axis maps to the IMU's −y.
  EXPECT_TRUE((c_bl * Eigen::Vector3d::UnitX()).isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
}

TrajectoryConfig TiltedConfig(bool vibration) {
  TrajectoryConfig c;
  c.length_m = 10;
  c.width_m = 5;
  c.speed_mps = 1.2;
  c.static_start_s = 1.0;
  c.ramp_s = 1.5;
  c.heading_rad = 0.3;
  c.ground_roll_rad = 3 * kRadPerDeg;
  c.ground_pitch_rad = 8 * kRadPerDeg;
  c.imu_height_m = 0.3;
  c.vehicle_from_imu = geometry::RotationFromEuler123Deg(Eigen::Vector3d(180, 0, 0));
  if (vibration) {
    c.vibration_roll_rad = 0.5 * kRadPerDeg;
    c.vibration_pitch_rad = 0.4 * kRadPerDeg;
    c.vibration_frequency_hz = 3.0;
  }
  return c;
}

// vee of the skew part of a rotation close to identity (small-angle log).
Eigen::Vector3d SmallLog(const Eigen::Matrix3d& r) {
  const Eigen::Matrix3d s = 0.5 * (r - r.transpose());
  const Eigen::Vector3d axis_sin(s(2, 1), s(0, 2), s(1, 0));
  const double sin_angle = axis_sin.norm();
  if (sin_angle < 1e-15) return Eigen::Vector3d::Zero();
  return axis_sin * (std::asin(sin_angle) / sin_angle);
}

TEST(SimTrajectoryTest, DerivativesMatchFiniteDifferences) {
  for (bool vibration : {false, true}) {
    const PlanarTrajectory trajectory(TiltedConfig(vibration));
    const double h = 1e-5;
    for (double t = 0.3; t < 25.0; t += 0.37) {
      SCOPED_TRACE("t = " + std::to_string(t) + (vibration ? " vibration" : ""));
      const ImuState s = trajectory.Evaluate(t);
      const ImuState sp = trajectory.Evaluate(t + h), sm = trajectory.Evaluate(t - h);
      EXPECT_TRUE(((sp.position_w - sm.position_w) / (2 * h)).isApprox(s.velocity_w, 1e-6) ||
                  s.velocity_w.norm() < 1e-9);
      EXPECT_LT(((sp.velocity_w - sm.velocity_w) / (2 * h) - s.acceleration_w).norm(), 1e-5);
      // ω_b from C(t−h)^T C(t+h) = Exp(2h ω_b).
      const Eigen::Vector3d omega_fd =
          SmallLog(sm.world_from_imu.transpose() * sp.world_from_imu) / (2 * h);
      EXPECT_LT((omega_fd - s.angular_velocity_b).norm(), 1e-6);
      // Pose() is Evaluate()'s pose.
      Eigen::Matrix3d c;
      Eigen::Vector3d r;
      trajectory.Pose(t, &c, &r);
      EXPECT_LT((c - s.world_from_imu).norm(), 1e-12);
      EXPECT_LT((r - s.position_w).norm(), 1e-12);
    }
  }
}

TEST(SimTrajectoryTest, PlanarMotionOnTheTiltedPlane) {
  const TrajectoryConfig config = TiltedConfig(false);
  const PlanarTrajectory trajectory(config);
  const Eigen::Vector3d n = trajectory.NormalInWorld();
  // The plane normal is tilted by roll 3, pitch 8 deg: acos(cos3 cos8).
  EXPECT_NEAR(std::acos(n.z()), std::acos(std::cos(3 * kRadPerDeg) * std::cos(8 * kRadPerDeg)),
              1e-12);
  double min_yaw_rate = 0, max_yaw_rate = 0;
  for (double t = 0; t < 30.0; t += 0.05) {
    const ImuState s = trajectory.Evaluate(t);
    EXPECT_NEAR(n.dot(s.position_w), config.imu_height_m, 1e-12);  // IMU at height d_b
    EXPECT_NEAR(n.dot(s.velocity_w), 0, 1e-12);
    EXPECT_NEAR(n.dot(s.acceleration_w), 0, 1e-12);
    // Vehicle z (= −IMU z, the IMU is upside down) along the normal.
    EXPECT_LT((s.world_from_imu * -Eigen::Vector3d::UnitZ() - n).norm(), 1e-12);
    // Angular velocity along the normal only (yaw about the plane normal).
    EXPECT_NEAR((s.world_from_imu * s.angular_velocity_b).cross(n).norm(), 0, 1e-12);
    if (t < config.static_start_s) {
      EXPECT_EQ(s.velocity_w.norm(), 0.0);
      EXPECT_EQ(s.angular_velocity_b.norm(), 0.0);
    }
    min_yaw_rate = std::min(min_yaw_rate, s.yaw_rate_radps);
    max_yaw_rate = std::max(max_yaw_rate, s.yaw_rate_radps);
  }
  // The figure-eight turns both ways.
  EXPECT_LT(min_yaw_rate, -0.3);
  EXPECT_GT(max_yaw_rate, 0.3);
}

TEST(SimTrajectoryTest, PeakYawRateCanBeSet) {
  for (const double target : {0.3, 0.8}) {
    TrajectoryConfig config = TiltedConfig(false);
    config.max_yaw_rate_radps = target;
    const PlanarTrajectory trajectory(config);
    EXPECT_NEAR(trajectory.length_m() / trajectory.width_m(), config.length_m / config.width_m,
                1e-12);
    double peak = 0.0;
    const double start = config.static_start_s + config.ramp_s;
    for (double t = start; t < start + trajectory.loop_period_s(); t += 0.001) {
      peak = std::max(peak, std::abs(trajectory.Evaluate(t).yaw_rate_radps));
    }
    EXPECT_NEAR(peak, target, 1e-3 * target);
    EXPECT_NEAR(trajectory.max_yaw_rate_radps(), target, 1e-9);
    // The speed stays as configured: one loop is the arc length at speed_mps.
    EXPECT_NEAR(trajectory.arc_length_m() / trajectory.loop_period_s(), config.speed_mps, 1e-12);
  }
}

TEST(SimWorldTest, SimpleHits) {
  World world(Eigen::Vector3d::UnitZ(), 10.0, 3.0);
  world.AddBox({4, 5, -0.5, 0.5, 2.0});
  world.AddPillar({-4, 0, 0.5, 2.0});
  RayHit hit;
  ASSERT_TRUE(world.Cast(Eigen::Vector3d(0, 0, 1), -Eigen::Vector3d::UnitZ(), 0.1, 100, &hit));
  EXPECT_NEAR(hit.range, 1.0, 1e-12);
  EXPECT_EQ(hit.surface, Surface::kGround);
  ASSERT_TRUE(world.Cast(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitX(), 0.1, 100, &hit));
  EXPECT_NEAR(hit.range, 4.0, 1e-12);
  EXPECT_EQ(hit.surface, Surface::kBox);
  ASSERT_TRUE(world.Cast(Eigen::Vector3d(0, 0, 1), -Eigen::Vector3d::UnitX(), 0.1, 100, &hit));
  EXPECT_NEAR(hit.range, 3.5, 1e-12);
  EXPECT_EQ(hit.surface, Surface::kPillar);
  ASSERT_TRUE(world.Cast(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitY(), 0.1, 100, &hit));
  EXPECT_NEAR(hit.range, 10.0, 1e-12);
  EXPECT_EQ(hit.surface, Surface::kWall);
  EXPECT_FALSE(world.Cast(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::UnitZ(), 0.1, 100, &hit));
  EXPECT_FALSE(world.Cast(Eigen::Vector3d(0, 0, 1), -Eigen::Vector3d::UnitZ(), 0.1, 0.5, &hit));
}

// Inside a solid (below the ground, in a box, in a pillar, in a wall band)?
bool InsideSolid(const World& world, double half, double wall_height, const Eigen::Vector3d& p) {
  const double gz = world.GroundZ(p.x(), p.y());
  if (p.z() < gz) return true;
  if ((std::abs(p.x()) > half || std::abs(p.y()) > half) && p.z() < gz + wall_height) return true;
  for (const Box& b : world.boxes()) {
    if (p.x() > b.min_x && p.x() < b.max_x && p.y() > b.min_y && p.y() < b.max_y &&
        p.z() < b.top_z) {
      return true;
    }
  }
  for (const Pillar& c : world.pillars()) {
    if (std::hypot(p.x() - c.center_x, p.y() - c.center_y) < c.radius && p.z() < c.top_z) {
      return true;
    }
  }
  return false;
}

TEST(SimWorldTest, CastAgreesWithBruteForceRayMarch) {
  const Eigen::Vector3d n = (geometry::RotationFromEuler123Deg(Eigen::Vector3d(3, 8, 0)) *
                             Eigen::Vector3d::UnitZ());
  const double half = 12, wall = 3;
  World world(n, half, wall);
  Rng rng(11);
  for (int i = 0; i < 8; ++i) {
    const double x = rng.Uniform(-9, 9), y = rng.Uniform(-9, 9);
    if (std::hypot(x, y) < 2.5) continue;
    if (i % 2 == 0) {
      world.AddBox({x - 0.6, x + 0.6, y - 0.4, y + 0.4, world.GroundZ(x, y) + 1.5});
    } else {
      world.AddPillar({x, y, 0.3, world.GroundZ(x, y) + 3.0});
    }
  }
  const Eigen::Vector3d origin = 0.8 * n;
  const double step = 0.005;
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    const double az = rng.Uniform(-M_PI, M_PI), el = rng.Uniform(-0.5, 0.3);
    const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                            std::sin(el));
    RayHit hit;
    const bool got = world.Cast(origin, d, 0.1, 40.0, &hit);
    double marched = -1;
    for (double s = 0.1; s <= 40.0; s += step) {
      if (InsideSolid(world, half, wall, origin + s * d)) {
        marched = s;
        break;
      }
    }
    ASSERT_EQ(got, marched >= 0) << "ray " << i;
    if (got) {
      ++hits;
      EXPECT_NEAR(hit.range, marched, step + 1e-9) << "ray " << i;
      EXPECT_NEAR(hit.normal.norm(), 1.0, 1e-12);
      EXPECT_LT(hit.normal.dot(d), 0.0);  // facing the sensor
    }
  }
  EXPECT_GT(hits, 200);
}

TEST(SimLidarModelTest, RingsAndFiring) {
  for (const LidarModel& m : {Vlp16Model(), Vlp32cModel(), Os132Model(1024)}) {
    SCOPED_TRACE(m.name);
    std::vector<int> seen(m.num_lasers(), 0);
    for (int i = 0; i < m.num_lasers(); ++i) ++seen[m.ring[i]];
    for (int r = 0; r < m.num_lasers(); ++r) EXPECT_EQ(seen[r], 1);
    for (int i = 0; i < m.num_lasers(); ++i) {
      for (int j = 0; j < m.num_lasers(); ++j) {
        // Velodyne: ring increases with elevation; Ouster: row 0 on top.
        if (m.kind == LidarModel::Kind::kVelodyne && m.elevation_rad[i] < m.elevation_rad[j]) {
          EXPECT_LT(m.ring[i], m.ring[j]);
        }
        if (m.kind == LidarModel::Kind::kOuster && m.elevation_rad[i] > m.elevation_rad[j]) {
          EXPECT_LT(m.ring[i], m.ring[j]);
        }
      }
    }
  }
  ScanConfig config;
  config.model = Vlp16Model();
  config.scan_rate_hz = 10;
  // 1808 firing sequences of 55.296 µs fit in 0.1 s; the last laser fires
  // 15 x 2.304 µs into the last one.
  EXPECT_NEAR(SweepSpanS(config), 1807 * 55.296e-6 + 15 * 2.304e-6, 1e-12);
  EXPECT_EQ(SweepStartNs(config, 3), std::llround((0.1 + 0.3) * 1e9));
}

TEST(SimScanSimulatorTest, PointTimesFollowTheStampConvention) {
  TrajectoryConfig tc = TiltedConfig(false);
  const PlanarTrajectory trajectory(tc);
  World world(trajectory.NormalInWorld(), 20, 3);
  for (const bool at_start : {false, true}) {
    ScanConfig config;
    config.model = Vlp16Model();
    config.velodyne_stamp_at_start = at_start;
    config.range_noise_m = 0.01;
    config.imu_from_lidar_rotation = geometry::RotationFromEuler123Deg(Eigen::Vector3d(180, 0, -90));
    config.imu_from_lidar_translation = Eigen::Vector3d(0.2477, -0.0699, -0.4636);
    const SimulatedScan scan = SimulateSweep(config, trajectory, world, 5, 2);
    ASSERT_GT(scan.points.size(), 10000u);
    float lo = 1e9f, hi = -1e9f;
    for (const ScanPoint& p : scan.points) {
      lo = std::min(lo, p.time_s);
      hi = std::max(hi, p.time_s);
    }
    const double span = SweepSpanS(config);
    if (at_start) {
      EXPECT_GE(lo, 0.0f);
      EXPECT_LE(hi, span + 1e-6);
      EXPECT_EQ(scan.stamp_true_ns, SweepStartNs(config, 2));
    } else {  // driver default: stamp at the end of the sweep, times ≤ 0
      EXPECT_LE(hi, 0.0f);
      EXPECT_GE(lo, -span - 1e-6);
      EXPECT_EQ(scan.stamp_true_ns, SweepStartNs(config, 2) + std::llround(span * 1e9));
    }
    EXPECT_GT(hi - lo, 0.99 * span);
  }
  // Same seed and sweep: the same points; another sweep index: other noise.
  ScanConfig config;
  config.model = Os132Model(512);
  const SimulatedScan a = SimulateSweep(config, trajectory, world, 5, 4);
  const SimulatedScan b = SimulateSweep(config, trajectory, world, 5, 4);
  ASSERT_EQ(a.points.size(), 32u * 512u);
  size_t same = 0;
  for (size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].range_mm, b.points[i].range_mm);
    same += a.points[i].valid == b.points[i].valid;
    EXPECT_LT(a.points[i].time_ns, 100000000u);
  }
  EXPECT_EQ(same, a.points.size());
}

// Livox frames: every point in time order at the model's rate, lines taken
// in turn, directions inside the field of view, no return at the origin, and
// a pattern that does not repeat (three frames cover more directions than one).
TEST(SimScanSimulatorTest, LivoxFramesAreNonRepetitiveWithinTheFieldOfView) {
  TrajectoryConfig tc = TiltedConfig(false);
  const PlanarTrajectory trajectory(tc);
  World world(trajectory.NormalInWorld(), 20, 3);
  for (const bool avia : {true, false}) {
    SCOPED_TRACE(avia ? "Avia" : "Mid-360");
    ScanConfig config;
    config.model = avia ? LivoxAviaModel() : LivoxMid360Model();
    const int lines = avia ? 6 : 4;
    const size_t expected_points = avia ? 24000 : 20000;
    std::set<std::pair<int, int>> one_frame, three_frames;  // 1 x 1 deg direction cells
    for (int k = 2; k < 5; ++k) {
      const SimulatedScan scan = SimulateSweep(config, trajectory, world, 5, k);
      ASSERT_EQ(scan.points.size(), expected_points);
      EXPECT_EQ(scan.stamp_true_ns, SweepStartNs(config, k));
      int valid = 0;
      for (size_t j = 0; j < scan.points.size(); ++j) {
        const ScanPoint& p = scan.points[j];
        EXPECT_EQ(p.ring, j % lines);
        if (j > 0) {
          EXPECT_GT(p.time_ns, scan.points[j - 1].time_ns);
        }
        if (!p.valid) {
          EXPECT_TRUE(p.x == 0.0f && p.y == 0.0f && p.z == 0.0f);
          continue;
        }
        ++valid;
        const double az = geometry::RadToDeg(std::atan2(p.y, p.x));
        const double el = geometry::RadToDeg(std::atan2(p.z, std::hypot(p.x, p.y)));
        if (avia) {
          EXPECT_LE(std::abs(az), 35.2 + 1e-3);
          EXPECT_LE(std::abs(el), 38.6 + 1e-3);
        } else {
          EXPECT_GE(el, -7.0 - 1e-3);
          EXPECT_LE(el, 52.0 + 1e-3);
        }
        const std::pair<int, int> cell(static_cast<int>(std::floor(az)),
                                       static_cast<int>(std::floor(el)));
        if (k == 2) one_frame.insert(cell);
        three_frames.insert(cell);
      }
      EXPECT_GT(valid, static_cast<int>(expected_points / 4));
      EXPECT_LT(scan.points.back().time_ns, 100000000u);
    }
    EXPECT_GT(three_frames.size(), one_frame.size() * 6 / 5);
  }
}

TEST(SimRngTest, DeterministicAndNormal) {
  Rng a(9, 2), b(9, 2), c(9, 3);
  EXPECT_EQ(a.NextU64(), b.NextU64());
  EXPECT_NE(b.NextU64(), c.NextU64());
  Rng g(1);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double x = g.Gaussian();
    sum += x;
    sum2 += x * x;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum2 / n, 1.0, 0.01);
}

}  // namespace
}  // namespace tiltcal::simulate
