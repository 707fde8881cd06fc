#include "stages/calibrate/report/map_sharpness.h"

#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::calibrate {
namespace {

// A surfel of voxel (x, 0, 0) whose points lie thickness_m from its plane (RMS).
Surfel SurfelAt(int x, double thickness_m) {
  Surfel s;
  s.voxel = Eigen::Vector3i(x, 0, 0);
  s.eigenvalues_m2 = Eigen::Vector3d(1.0, 0.5, thickness_m * thickness_m);
  return s;
}

// A blurred map keeps only its thinnest voxels planar: over its own surfels
// its median looks sharper than the sharp map's, over the common voxels it
// is thicker.
TEST(CompareSurfelThicknessTest, ComparesTheVoxelsPlanarInBothMaps) {
  const std::vector<Surfel> sharp = {SurfelAt(0, 0.001), SurfelAt(1, 0.001), SurfelAt(2, 0.002),
                                     SurfelAt(3, 0.002), SurfelAt(4, 0.002)};
  const std::vector<Surfel> blurred = {SurfelAt(0, 0.0015), SurfelAt(1, 0.0015),
                                       SurfelAt(5, 0.003)};
  const MapSharpnessComparison c = CompareSurfelThickness(sharp, blurred);
  EXPECT_EQ(c.state.planar_surfels(), 5);
  EXPECT_EQ(c.other.planar_surfels(), 3);
  EXPECT_EQ(c.state.common_surfels(), 2);
  EXPECT_EQ(c.other.common_surfels(), 2);
  EXPECT_NEAR(c.state.median_thickness_m(), 0.001, 1e-12);
  EXPECT_NEAR(c.other.median_thickness_m(), 0.0015, 1e-12);
  // The other way round: the same numbers, swapped.
  const MapSharpnessComparison swapped = CompareSurfelThickness(blurred, sharp);
  EXPECT_NEAR(swapped.state.median_thickness_m(), 0.0015, 1e-12);
  EXPECT_NEAR(swapped.other.median_thickness_m(), 0.001, 1e-12);
}

TEST(CompareSurfelThicknessTest, NoCommonVoxelGivesZeroThickness) {
  const MapSharpnessComparison c =
      CompareSurfelThickness({SurfelAt(0, 0.001)}, {SurfelAt(1, 0.001)});
  EXPECT_EQ(c.state.common_surfels(), 0);
  EXPECT_EQ(c.state.median_thickness_m(), 0.0);
  EXPECT_EQ(c.other.median_thickness_m(), 0.0);
  EXPECT_EQ(c.state.planar_surfels(), 1);
  const MapSharpnessComparison empty = CompareSurfelThickness({}, {});
  EXPECT_EQ(empty.state.planar_surfels(), 0);
  EXPECT_EQ(empty.state.median_thickness_m(), 0.0);
}

// Voxels are matched by all three indices, in the maps' (x, y, z) order.
TEST(CompareSurfelThicknessTest, MatchesVoxelsByAllThreeIndices) {
  Surfel a0 = SurfelAt(0, 0.001), a1 = SurfelAt(0, 0.001), b0 = SurfelAt(0, 0.004),
         b1 = SurfelAt(0, 0.004);
  a0.voxel = Eigen::Vector3i(0, -1, 2);
  a1.voxel = Eigen::Vector3i(0, 1, 0);
  b0.voxel = Eigen::Vector3i(0, -1, 3);
  b1.voxel = Eigen::Vector3i(0, 1, 0);
  const MapSharpnessComparison c = CompareSurfelThickness({a0, a1}, {b0, b1});
  EXPECT_EQ(c.state.common_surfels(), 1);
  EXPECT_NEAR(c.other.median_thickness_m(), 0.004, 1e-12);
}

}  // namespace
}  // namespace tiltcal::calibrate
