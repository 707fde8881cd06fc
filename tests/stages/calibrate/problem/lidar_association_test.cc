// BuildMapAndAssociate on one thread and on several: the same map, the same
// associations in the same order.

#include "stages/calibrate/problem/lidar_association.h"

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include "stages/calibrate/problem/dense_sample_weight.h"
#include "tests/stages/calibrate/calibrate_params_text.h"

namespace tiltcal::calibrate {
namespace {

// The final round's weight: four times the points at exponent 0.5 carry
// twice the information (sigma x 2^(1/2), so 4 / 2 = 2 times the summed
// 1 / sigma^2); the Cauchy loss bends at the same distance in metres.
TEST(DenseSampleLidarParams, InformationGrowsAsTheDensityToTheExponent) {
  proto::LidarResidualParams lidar;
  lidar.set_sigma_m(0.02);
  lidar.set_cauchy_scale(2.0);
  const proto::LidarResidualParams dense = DenseSampleLidarParams(lidar, 4000, 1000, 0.5);
  const double information_ratio =
      (4000.0 / (dense.sigma_m() * dense.sigma_m())) / (1000.0 / (0.02 * 0.02));
  EXPECT_NEAR(information_ratio, 2.0, 1e-12);
  EXPECT_NEAR(dense.cauchy_scale() * dense.sigma_m(), 2.0 * 0.02, 1e-15);
  // Exponent 1: every point counts in full; 0: the reference's information.
  EXPECT_DOUBLE_EQ(DenseSampleLidarParams(lidar, 4000, 1000, 1.0).sigma_m(), 0.02);
  EXPECT_NEAR(DenseSampleLidarParams(lidar, 4000, 1000, 0.0).sigma_m(), 0.04, 1e-15);
  // No reference, or no denser: unchanged.
  EXPECT_DOUBLE_EQ(DenseSampleLidarParams(lidar, 4000, 0, 0.5).sigma_m(), 0.02);
  EXPECT_DOUBLE_EQ(DenseSampleLidarParams(lidar, 900, 1000, 0.5).cauchy_scale(), 2.0);
}

// A LiDAR driving at 1 m/s along x and yawing at 0.2 rad/s through a room
// (floor z = -1.5, walls y = +-6, x = 20), 40 scans at 10 Hz of 2,000
// points with 1 cm of noise, C_bl = 1 and r_b^{lb} = 0.
struct Room {
  CalibrationState state{spline::UniformKnotGrid::ForDuration(0.0, 4.5, 0.05)};
  std::vector<LidarScan> scans;
};

Room MakeRoom() {
  Room room;
  room.state.SetImuFromLidarRotation(Eigen::Quaterniond::Identity());
  room.state.SetImuFromLidarTranslation(Eigen::Vector3d::Zero());
  room.state.time_offset_s[0] = 0.0;
  spline::SplineTrajectory& traj = room.state.trajectory;
  const double dt = traj.grid().dt_s();
  for (int i = 0; i < traj.num_knots(); ++i) {
    const double t = traj.grid().t0_s() + (i - 1) * dt;
    traj.SetRotationKnot(i, Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * t, Eigen::Vector3d::UnitZ())));
    traj.SetPositionKnot(i, Eigen::Vector3d(t, 0.0, 0.0));
  }
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (int k = 0; k < 40; ++k) {
    LidarScan scan;
    scan.index = k;
    scan.stamp_s = 0.2 + 0.1 * k;
    for (int j = 0; j < 2000; ++j) {
      const double time_s = -0.1 + 0.1 * j / 2000.0;
      spline::So3SplineSample rot;
      spline::R3SplineSample pos;
      if (!traj.Evaluate(scan.stamp_s + time_s, spline::kSo3Rotation, &rot, &pos)) continue;
      Eigen::Vector3d p_a;
      switch (j % 4) {
        case 0: p_a = Eigen::Vector3d(pos.position.x() + 8.0 * u(rng), 5.0 * u(rng), -1.5); break;
        case 1: p_a = Eigen::Vector3d(pos.position.x() + 8.0 * u(rng), 6.0, 1.5 * u(rng)); break;
        case 2: p_a = Eigen::Vector3d(pos.position.x() + 8.0 * u(rng), -6.0, 1.5 * u(rng)); break;
        default: p_a = Eigen::Vector3d(20.0, 5.0 * u(rng), 1.5 * u(rng)); break;
      }
      p_a += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
      const Eigen::Vector3d p_l = rot.rotation.transpose() * (p_a - pos.position);
      scan.points.push_back(p_l.cast<float>());
      scan.point_time_s.push_back(static_cast<float>(time_s));
    }
    scan.min_time_s = scan.point_time_s.front();
    scan.max_time_s = scan.point_time_s.back();
    room.scans.push_back(std::move(scan));
  }
  return room;
}

TEST(LidarAssociationTest, SameMapAndAssociationsOnAnyNumberOfThreads) {
  const Room room = MakeRoom();
  const proto::CalibrateParams params = testing::DefaultCalibrateParamsWith();
  std::vector<LidarPointResidual> one;
  AssociationStageSummary one_summary;
  BuildMapAndAssociate(room.state, room.scans, params.map(), params.association(), 1, &one,
                       &one_summary);
  ASSERT_EQ(one_summary.scans_mapped, 40);
  ASSERT_GT(one.size(), 40u * 20u) << "most scans should reach their cap of associations";
  // The associations lie on the room's planes.
  for (const LidarPointResidual& r : one) {
    EXPECT_NEAR(std::abs(r.plane_normal.norm()), 1.0, 1e-9);
    const bool known = std::abs(std::abs(r.plane_normal.z()) - 1.0) < 0.01 ||
                       std::abs(std::abs(r.plane_normal.y()) - 1.0) < 0.01 ||
                       std::abs(std::abs(r.plane_normal.x()) - 1.0) < 0.01;
    EXPECT_TRUE(known) << r.plane_normal.transpose();
  }
  for (const int threads : {2, 3}) {
    std::vector<LidarPointResidual> many;
    AssociationStageSummary summary;
    BuildMapAndAssociate(room.state, room.scans, params.map(), params.association(), threads,
                         &many, &summary);
    EXPECT_EQ(summary.scans_mapped, one_summary.scans_mapped);
    EXPECT_EQ(summary.points_mapped, one_summary.points_mapped);
    EXPECT_EQ(summary.map.num_surfels, one_summary.map.num_surfels);
    EXPECT_EQ(summary.surfels_used, one_summary.surfels_used);
    ASSERT_EQ(many.size(), one.size()) << threads << " threads";
    for (std::size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(many[i].time_s, one[i].time_s) << i;
      EXPECT_EQ(many[i].point_lidar_m, one[i].point_lidar_m) << i;
      EXPECT_EQ(many[i].plane_normal, one[i].plane_normal) << i;
      EXPECT_EQ(many[i].plane_offset_m, one[i].plane_offset_m) << i;
    }
  }
}

}  // namespace
}  // namespace tiltcal::calibrate
