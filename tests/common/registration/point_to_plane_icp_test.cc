#include "common/registration/point_to_plane_icp.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/geometry/so3.h"
#include "tests/common/registration/registration_test_options.h"
#include "tests/common/registration/synthetic_scene.h"

namespace tiltcal::registration {
namespace {

using testing::PointToPlaneIcpTestOptions;
using testing::VoxelHashMapTestOptions;

Eigen::Isometry3d Pose(const Eigen::Vector3d& rotation_vector_rad, const Eigen::Vector3d& t_m) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = geometry::ExpQuaternion(rotation_vector_rad).toRotationMatrix();
  pose.translation() = t_m;
  return pose;
}

double AngleBetween(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

// The residual's Jacobian against central differences of
// r(delta) = n . (Exp(dphi) p' + dt - q).
TEST(PointToPlaneIcpTest, JacobianMatchesFiniteDifferences) {
  const Eigen::Vector3d p_map(3.0, -2.0, 1.5), q(2.9, -2.2, 1.4);
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.4, 0.866).normalized();
  Eigen::Matrix<double, 1, 6> analytic;
  const double r0 = PointToPlaneResidual(p_map, q, n, &analytic);
  EXPECT_NEAR(r0, n.dot(p_map - q), 1e-15);
  const double h = 1e-6;
  for (int k = 0; k < 6; ++k) {
    Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
    auto residual_at = [&](double step) {
      delta[k] = step;
      const Eigen::Isometry3d update = Pose(delta.tail<3>(), delta.head<3>());
      return PointToPlaneResidual(update * p_map, q, n, nullptr);
    };
    const double numeric = (residual_at(h) - residual_at(-h)) / (2 * h);
    EXPECT_NEAR(analytic[k], numeric, 1e-8) << "column " << k;
  }
}

struct Scene {
  std::vector<Eigen::Vector3d> source;  // the room seen from the source frame
  VoxelHashMap map{VoxelHashMapTestOptions()};
  Eigen::Isometry3d truth;               // map_from_source
};

Scene MakeScene(const Eigen::Isometry3d& truth, double noise_m,
                const VoxelHashMapOptions& map_options = VoxelHashMapTestOptions()) {
  Scene scene{{}, VoxelHashMap(map_options), truth};
  scene.map.AddPoints(testing::SyntheticRoom(0.1, noise_m, 1));
  const Eigen::Isometry3d source_from_map = truth.inverse();
  for (const Eigen::Vector3d& p : testing::SyntheticRoom(0.37, noise_m, 2)) {
    scene.source.push_back(source_from_map * p);
  }
  return scene;
}

TEST(PointToPlaneIcpTest, RecoversAKnownRigidTransform) {
  // Noise-free planes: only voxels on one plane pass a 5 mm thickness gate,
  // and a 1 cm kernel scale leaves out pairs across a corner (a wall point
  // whose nearest map point lies on the floor).
  VoxelHashMapOptions map_options = VoxelHashMapTestOptions();
  map_options.max_plane_thickness_m = 0.005;
  const Scene scene =
      MakeScene(Pose({0.02, -0.03, 0.25}, {0.4, -0.3, 0.1}), 0.0, map_options);
  PointToPlaneIcpOptions options = PointToPlaneIcpTestOptions();
  options.kernel_scale_m = 0.01;
  options.max_iterations = 30;
  options.convergence_rotation_rad = 1e-7;
  options.convergence_translation_m = 1e-7;
  options.num_threads = 2;
  // Start 5 cm and ~1 deg away from the truth.
  const Eigen::Isometry3d initial = Pose({0.01, 0.0, -0.015}, {0.03, -0.04, 0.0}) * scene.truth;
  const PointToPlaneIcpResult result =
      AlignPointToPlane(scene.source, scene.map, initial, options);
  ASSERT_TRUE(result.registered);
  EXPECT_TRUE(result.converged);
  EXPECT_LT((result.map_from_source.translation() - scene.truth.translation()).norm(), 1e-6);
  EXPECT_LT(AngleBetween(result.map_from_source, scene.truth), 1e-7);
  EXPECT_GT(result.num_inliers, static_cast<int>(scene.source.size()) * 9 / 10);
  EXPECT_LT(result.inlier_rms_m, 1e-6);
}

TEST(PointToPlaneIcpTest, NoisyScanLandsWithinTheNoise) {
  const Scene scene = MakeScene(Pose({0.0, 0.01, -0.4}, {-1.0, 0.5, 0.0}), 0.01);
  PointToPlaneIcpOptions options = PointToPlaneIcpTestOptions();
  const Eigen::Isometry3d initial = Pose({0.0, 0.0, 0.03}, {0.1, 0.1, 0.0}) * scene.truth;
  const PointToPlaneIcpResult result =
      AlignPointToPlane(scene.source, scene.map, initial, options);
  ASSERT_TRUE(result.registered);
  EXPECT_LT((result.map_from_source.translation() - scene.truth.translation()).norm(), 0.01);
  EXPECT_LT(AngleBetween(result.map_from_source, scene.truth), geometry::DegToRad(0.1));
  EXPECT_NEAR(result.inlier_rms_m, 0.014, 0.008);  // two planes' noise of 1 cm
}

TEST(PointToPlaneIcpTest, TooFewCorrespondencesIsNotRegistered) {
  const Scene scene = MakeScene(Eigen::Isometry3d::Identity(), 0.0);
  PointToPlaneIcpOptions options = PointToPlaneIcpTestOptions();
  // 100 m away: no map point within the gate.
  const PointToPlaneIcpResult result = AlignPointToPlane(
      scene.source, scene.map, Pose({0, 0, 0}, {100.0, 0.0, 0.0}), options);
  EXPECT_FALSE(result.registered);
  EXPECT_EQ(result.num_correspondences, 0);
  EXPECT_EQ(result.map_from_source.translation().x(), 100.0);
}

}  // namespace
}  // namespace tiltcal::registration
