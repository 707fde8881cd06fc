#include "common/registration/voxel_hash_map.h"

#include <vector>

#include <gtest/gtest.h>

#include "tests/common/registration/registration_test_options.h"
#include "tests/common/registration/synthetic_scene.h"

namespace tiltcal::registration {
namespace {

using testing::VoxelHashMapTestOptions;

TEST(VoxelHashMapTest, VoxelOfFloorsNegativeCoordinates) {
  EXPECT_EQ(VoxelOf({-0.1, 0.0, 1.99}, 1.0), Eigen::Vector3i(-1, 0, 1));
  EXPECT_EQ(VoxelOf({2.5, -2.5, 0.49}, 0.5), Eigen::Vector3i(5, -5, 0));
}

TEST(VoxelHashMapTest, CapsPointsPerVoxelAndFitsThinPlanes) {
  VoxelHashMapOptions options = VoxelHashMapTestOptions();
  options.voxel_m = 1.0;
  options.max_points_per_voxel = 4;  // points at least 1 / sqrt(4) = 0.5 m apart
  options.min_plane_points = 4;
  options.max_plane_thickness_m = 0.05;
  VoxelHashMap map(options);
  std::vector<Eigen::Vector3d> floor;  // 16 points in voxel (0, 0, 0), plane z = 0.5
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) floor.push_back({0.05 + 0.25 * i, 0.05 + 0.25 * j, 0.5});
  }
  map.AddPoints(floor);
  EXPECT_EQ(map.num_voxels(), 1u);
  // Kept: (0.05, 0.05), (0.05, 0.55), (0.55, 0.05), (0.55, 0.55); the
  // others lie within 0.5 m of one of them, or come after the cap.
  EXPECT_EQ(map.num_points(), 4u);
  ASSERT_EQ(map.num_planes(), 1u);
  PlaneNeighbour n;
  ASSERT_TRUE(map.FindNearestOnPlane({0.06, 0.06, 0.7}, 0.5, &n));
  EXPECT_NEAR(std::abs(n.normal.z()), 1.0, 1e-9);
  EXPECT_EQ(n.point, floor[0]);
  // The plane passes through the mean of the four kept points.
  EXPECT_TRUE(n.centroid.isApprox(Eigen::Vector3d(0.3, 0.3, 0.5), 1e-12));
  EXPECT_NEAR(n.distance_m, (floor[0] - Eigen::Vector3d(0.06, 0.06, 0.7)).norm(), 1e-12);
  // From the voxel above: beyond a 0.5 m gate, within a 1 m one; two voxels
  // up, found with a gate that reaches that far.
  EXPECT_FALSE(map.FindNearestOnPlane({0.06, 0.06, 1.4}, 0.5, &n));
  EXPECT_TRUE(map.FindNearestOnPlane({0.06, 0.06, 1.4}, 1.0, &n));
  EXPECT_FALSE(map.FindNearestOnPlane({0.06, 0.06, 2.4}, 1.0, &n));
  EXPECT_TRUE(map.FindNearestOnPlane({0.06, 0.06, 2.4}, 2.0, &n));
}

TEST(VoxelHashMapTest, ALineOfPointsHasNoPlane) {
  VoxelHashMapOptions options = VoxelHashMapTestOptions();
  options.min_plane_points = 5;
  options.max_points_per_voxel = 100;  // points at least 0.1 m apart
  VoxelHashMap map(options);
  std::vector<Eigen::Vector3d> line;  // one scan line across the voxel, 5 mm wiggle
  for (int i = 0; i < 8; ++i) line.push_back({0.05 + 0.12 * i, 0.5 + 0.005 * (i % 2), 0.2});
  map.AddPoints(line);
  EXPECT_EQ(map.num_points(), line.size());
  EXPECT_EQ(map.num_planes(), 0u);
}

TEST(VoxelHashMapTest, ThickOrSparseVoxelsHaveNoPlane) {
  VoxelHashMapOptions options = VoxelHashMapTestOptions();
  options.max_plane_thickness_m = 0.05;
  VoxelHashMap map(options);
  std::vector<Eigen::Vector3d> blob;  // a 3D lattice: thickness ~0.3 m
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 2; ++k) blob.push_back({0.1 + 0.4 * i, 0.1 + 0.4 * j, 0.1 + 0.8 * k});
  map.AddPoints(blob);
  map.AddPoints({{5.1, 5.1, 5.1}, {5.2, 5.1, 5.1}});  // two points
  EXPECT_EQ(map.num_voxels(), 2u);
  EXPECT_EQ(map.num_planes(), 0u);
  PlaneNeighbour n;
  EXPECT_FALSE(map.FindNearestOnPlane({0.5, 0.5, 0.5}, 1.0, &n));
}

TEST(VoxelHashMapTest, RemovesFarVoxels) {
  VoxelHashMap map(VoxelHashMapTestOptions());
  map.AddPoints(testing::SyntheticRoom(0.2, 0.0, 1));
  const size_t before = map.num_voxels();
  map.RemoveFarFrom(Eigen::Vector3d(8, 0, 0), 5.0);
  EXPECT_LT(map.num_voxels(), before);
  EXPECT_GT(map.num_voxels(), 0u);
  PlaneNeighbour n;
  EXPECT_FALSE(map.FindNearestOnPlane({-9.5, 0, 0}, 1.0, &n));
  EXPECT_TRUE(map.FindNearestOnPlane({7.9, 0, 1}, 1.0, &n));
}

}  // namespace
}  // namespace tiltcal::registration
