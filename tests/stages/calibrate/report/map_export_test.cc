#include "stages/calibrate/report/map_export.h"

#include <cstring>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "tests/testing/test_env.h"

namespace tiltcal::calibrate {
namespace {

LidarScan Scan(int index, double stamp_s) {
  LidarScan scan;
  scan.index = index;
  scan.stamp_s = stamp_s;
  scan.points = {{1.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.5f}};
  scan.point_time_s = {0.0f, 0.05f};
  scan.min_time_s = 0.0;
  scan.max_time_s = 0.05;
  return scan;
}

// A vehicle standing still at r_a^{ba} = (0.3, -0.2, 0.1), C_ab = 1: every
// map point is p_a = C_bl p_l + r_b^{lb} + r_a^{ba}, with the extrinsic given
// to BuildMapPoints, not the state's.
TEST(MapExport, PointsAreMovedWithTheGivenExtrinsicAndEveryScanStep) {
  CalibrationState state(spline::UniformKnotGrid::ForDuration(0.0, 1.0, 0.05));
  const Eigen::Vector3d standing(0.3, -0.2, 0.1);
  for (int i = 0; i < state.trajectory.num_knots(); ++i) {
    state.trajectory.SetRotationKnot(i, Eigen::Quaterniond::Identity());
    state.trajectory.SetPositionKnot(i, standing);
  }
  state.SetImuFromLidarTranslation(Eigen::Vector3d(9, 9, 9));  // not used
  Rigid3d imu_from_lidar;
  imu_from_lidar.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  imu_from_lidar.translation = Eigen::Vector3d(1, 2, 3);
  const std::vector<LidarScan> scans = {Scan(10, 0.2), Scan(11, 0.4), Scan(12, 0.6)};
  proto::MapExportParams params;
  params.set_scan_step(2);

  const std::vector<MapPoint> points = BuildMapPoints(state, imu_from_lidar, scans, params, 0.005);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[0].scan_index, 10u);
  EXPECT_EQ(points[2].scan_index, 12u);
  // Rz(90°) (1, 0, 0) = (0, 1, 0); Rz(90°) (0, 2, 0.5) = (-2, 0, 0.5).
  EXPECT_TRUE(points[0].position_m.isApprox(Eigen::Vector3f(1.3f, 2.8f, 3.1f), 1e-5f));
  EXPECT_TRUE(points[1].position_m.isApprox(Eigen::Vector3f(-0.7f, 1.8f, 3.6f), 1e-5f));
}

TEST(MapExport, PcdIsBinaryXyzAndScan) {
  testing::TempDir dir;
  const std::string path = dir.File("map.pcd");
  ASSERT_TRUE(WriteMapPcd(path, {{{1.5f, -2.0f, 0.25f}, 7u}, {{0.0f, 1.0f, 2.0f}, 9u}}).ok());
  std::string text;
  ASSERT_TRUE(ReadFileToString(path, &text).ok());
  const std::string header =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z scan\n"
      "SIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA binary\n";
  ASSERT_EQ(text.substr(0, header.size()), header);
  ASSERT_EQ(text.size(), header.size() + 32);
  float xyz[3];
  uint32_t scan = 0;
  std::memcpy(xyz, text.data() + header.size() + 16, 12);
  std::memcpy(&scan, text.data() + header.size() + 28, 4);
  EXPECT_EQ(xyz[0], 0.0f);
  EXPECT_EQ(xyz[1], 1.0f);
  EXPECT_EQ(xyz[2], 2.0f);
  EXPECT_EQ(scan, 9u);
}

TEST(MapExport, UnwritablePathIsAnErrorNamingIt) {
  const Status status = WriteMapPcd("/nonexistent_dir/map.pcd", {});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("/nonexistent_dir/map.pcd"), std::string::npos)
      << status.message();
}

}  // namespace
}  // namespace tiltcal::calibrate
