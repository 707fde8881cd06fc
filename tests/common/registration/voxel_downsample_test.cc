#include "common/registration/voxel_downsample.h"

#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::registration {
namespace {

TEST(VoxelDownsampleTest, KeepsTheFirstPointPerVoxel) {
  const std::vector<Eigen::Vector3d> points = {
      {0.1, 0.1, 0.1}, {0.4, 0.2, 0.3},   // voxel (0, 0, 0) at 0.5 m
      {0.6, 0.1, 0.1},                    // voxel (1, 0, 0)
      {-0.1, 0.1, 0.1}, {-0.2, 0.4, 0.4}  // voxel (-1, 0, 0)
  };
  const std::vector<Eigen::Vector3d> kept = VoxelDownsample(points, 0.5);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept[0], points[0]);
  EXPECT_EQ(kept[1], points[2]);
  EXPECT_EQ(kept[2], points[3]);
}

TEST(VoxelDownsampleTest, NonPositiveVoxelKeepsEverything) {
  const std::vector<Eigen::Vector3d> points = {{0, 0, 0}, {0.01, 0, 0}};
  EXPECT_EQ(VoxelDownsample(points, 0.0).size(), 2u);
}

}  // namespace
}  // namespace tiltcal::registration
