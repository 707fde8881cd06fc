// SingleQueryKdTree against PCL's own pcl::search::KdTree: the same
// neighbours in the same order with the same distances (on a grid, where
// many points tie, the same distances, the tied points in any order), and
// the same GICP alignment to the last bit; ComputeGicpCovariances against GICP's own
// covariances (its closed-form eigenvector against PCL's SVD: equal to
// rounding), and GICP given them against GICP on its own.

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <pcl/common/transforms.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/search/kdtree.h>

#include "stages/calibrate/odometry/gicp_covariances.h"
#include "stages/calibrate/odometry/single_query_kd_tree.h"

namespace tiltcal::calibrate {
namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

// Points on three walls and a floor (where GICP's covariances are planar),
// with noise and, optionally, a few invalid points.
Cloud::Ptr RoomCloud(unsigned seed, int n, bool with_invalid) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  Cloud::Ptr cloud(new Cloud);
  for (int i = 0; i < n; ++i) {
    pcl::PointXYZ p(u(rng), u(rng), u(rng) * 0.3f);
    switch (i % 4) {
      case 0: p.z = -1.5f + noise(rng); break;
      case 1: p.x = 5.0f + noise(rng); break;
      case 2: p.y = -5.0f + noise(rng); break;
      default: p.y = 4.0f + 0.2f * p.x + noise(rng); break;
    }
    cloud->push_back(p);
    if (with_invalid && i % 97 == 0) {
      const float nan = std::numeric_limits<float>::quiet_NaN();
      cloud->push_back(pcl::PointXYZ(nan, 0.0f, nan));
    }
  }
  return cloud;
}

// SingleQueryKdTree never gives its cloud to the pcl::search::KdTree it
// derives from, so answers that came from there would be empty.
TEST(SingleQueryKdTreeTest, SameNeighboursAsPclKdTree) {
  for (const bool with_invalid : {false, true}) {
    const Cloud::Ptr cloud = RoomCloud(1, 3000, with_invalid);
    pcl::search::KdTree<pcl::PointXYZ> pcl_tree;
    SingleQueryKdTree tree;
    pcl_tree.setInputCloud(cloud);
    tree.setInputCloud(cloud);
    EXPECT_EQ(tree.getInputCloud(), cloud);
    const Cloud::Ptr queries = RoomCloud(2, 300, false);
    for (const pcl::PointXYZ& q : queries->points) {
      pcl::Indices expected_indices, indices;
      std::vector<float> expected_distances, distances;
      for (const int k : {1, 10, 20}) {
        ASSERT_EQ(tree.nearestKSearch(q, k, indices, distances),
                  pcl_tree.nearestKSearch(q, k, expected_indices, expected_distances));
        EXPECT_EQ(indices, expected_indices);
        EXPECT_EQ(distances, expected_distances);
      }
      for (const unsigned int max_nn : {0u, 5u}) {
        ASSERT_EQ(tree.radiusSearch(q, 0.8, indices, distances, max_nn),
                  pcl_tree.radiusSearch(q, 0.8, expected_indices, expected_distances, max_nn));
        EXPECT_EQ(indices, expected_indices);
        EXPECT_EQ(distances, expected_distances);
      }
    }
  }
}

// A grid of 0.25 m, queried at grid points and between them: neighbours at
// exactly the same distance everywhere. Both trees are exact, so the
// distances are PCL's, every index is a point at its distance, and only
// the order among tied points (and which tied point is the k-th) may differ.
TEST(SingleQueryKdTreeTest, TiedNeighboursHaveThePclDistances) {
  Cloud::Ptr grid(new Cloud);
  for (int i = 0; i < 12; ++i) {
    for (int j = 0; j < 12; ++j) {
      for (int l = 0; l < 6; ++l) grid->push_back(pcl::PointXYZ(0.25f * i, 0.25f * j, 0.25f * l));
    }
  }
  pcl::search::KdTree<pcl::PointXYZ> pcl_tree;
  SingleQueryKdTree tree;
  pcl_tree.setInputCloud(grid);
  tree.setInputCloud(grid);
  int queries_with_ties = 0;
  for (int q = 0; q < 200; ++q) {
    const pcl::PointXYZ& p = (*grid)[(q * 37) % grid->size()];
    const pcl::PointXYZ query(p.x + (q % 2) * 0.125f, p.y, p.z + (q % 3 == 0) * 0.125f);
    for (const int k : {1, 10}) {
      pcl::Indices expected_indices, indices;
      std::vector<float> expected_distances, distances;
      ASSERT_EQ(tree.nearestKSearch(query, k, indices, distances),
                pcl_tree.nearestKSearch(query, k, expected_indices, expected_distances));
      EXPECT_EQ(distances, expected_distances);
      for (size_t j = 0; j < indices.size(); ++j) {
        const pcl::PointXYZ& n = (*grid)[indices[j]];
        const float dx = query.x - n.x, dy = query.y - n.y, dz = query.z - n.z;
        EXPECT_EQ(dx * dx + dy * dy + dz * dz, distances[j]);
      }
      if (k == 10 && distances.size() == 10 && distances[0] == distances[1]) ++queries_with_ties;
    }
  }
  EXPECT_GT(queries_with_ties, 50);
}

using Gicp = pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ>;

// A room (target, `target_seed`) and another sample of it (source,
// `source_seed`) moved by a small rotation about `axis` and `translation`.
struct MovedRoom {
  Cloud::Ptr target;
  Cloud::Ptr source{new Cloud};
  Eigen::Affine3f motion = Eigen::Affine3f::Identity();
};

MovedRoom MakeMovedRoom(unsigned target_seed, unsigned source_seed, float angle_rad,
                        const Eigen::Vector3f& axis, const Eigen::Vector3f& translation) {
  MovedRoom room;
  room.target = RoomCloud(target_seed, 4000, false);
  room.motion.rotate(Eigen::AngleAxisf(angle_rad, axis.normalized()));
  room.motion.translation() = translation;
  pcl::transformPointCloud(*RoomCloud(source_seed, 2000, false), *room.source, room.motion);
  return room;
}

// GICP's final transformation on `room` after `set_up` gave it its clouds
// (and whatever else it sets).
Eigen::Matrix4f Align(const MovedRoom& room, const std::function<void(Gicp*)>& set_up) {
  Gicp gicp;
  gicp.setMaxCorrespondenceDistance(1.0);
  set_up(&gicp);
  Cloud aligned;
  gicp.align(aligned);
  EXPECT_TRUE(gicp.hasConverged());
  return gicp.getFinalTransformation();
}

// Both transformations are equal, and the first undid the motion.
void ExpectSameAlignmentThatUndidTheMotion(const MovedRoom& room, const Eigen::Matrix4f& first,
                                           const Eigen::Matrix4f& second) {
  EXPECT_EQ(second, first);
  EXPECT_LT((first * room.motion.matrix() - Eigen::Matrix4f::Identity()).norm(), 0.02f);
}

TEST(SingleQueryKdTreeTest, GicpAlignsExactlyAsWithPclKdTrees) {
  const MovedRoom room = MakeMovedRoom(3, 4, 0.05f, Eigen::Vector3f(0.2f, 0.1f, 1.0f),
                                       Eigen::Vector3f(0.2f, -0.1f, 0.05f));
  const Eigen::Matrix4f with_pcl_trees = Align(room, [&](Gicp* gicp) {
    gicp->setInputTarget(room.target);
    gicp->setInputSource(room.source);
  });
  const Eigen::Matrix4f with_own_trees = Align(room, [&](Gicp* gicp) {
    gicp->setSearchMethodTarget(std::make_shared<SingleQueryKdTree>());
    gicp->setSearchMethodSource(std::make_shared<SingleQueryKdTree>());
    gicp->setInputTarget(room.target);
    gicp->setInputSource(room.source);
  });
  ExpectSameAlignmentThatUndidTheMotion(room, with_pcl_trees, with_own_trees);
}

// GICP with its protected covariance computation made callable.
class GicpExposingCovariances : public Gicp {
 public:
  using Gicp::computeCovariances;
};

TEST(GicpCovariancesTest, SameAsPclToRoundingOnAnyNumberOfThreads) {
  const Cloud::Ptr cloud = RoomCloud(5, 3001, false);
  auto tree = std::make_shared<SingleQueryKdTree>();
  tree->setInputCloud(cloud);
  GicpExposingCovariances gicp;
  gicp.setCorrespondenceRandomness(10);
  GicpExposingCovariances::MatricesVector pcl_covariances;
  gicp.computeCovariances<pcl::PointXYZ>(cloud, tree, pcl_covariances);
  ASSERT_EQ(pcl_covariances.size(), cloud->size());
  GicpCovariances on_one_thread;
  ASSERT_TRUE(ComputeGicpCovariances(*cloud, *tree, 10, 0.001, 1, &on_one_thread));
  ASSERT_EQ(on_one_thread.size(), cloud->size());
  // Entries are O(1): PCL's JacobiSVD and the closed form agree to ~3e-14
  // where the smallest eigenvalue is separated from the others, as on
  // every point of these planes.
  double largest_difference = 0.0;
  for (std::size_t i = 0; i < cloud->size(); ++i) {
    largest_difference = std::max(
        largest_difference, (on_one_thread[i] - pcl_covariances[i]).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(largest_difference, 1e-9);
  for (const int threads : {2, 3}) {
    GicpCovariances covariances;
    ASSERT_TRUE(ComputeGicpCovariances(*cloud, *tree, 10, 0.001, threads, &covariances));
    ASSERT_EQ(covariances.size(), cloud->size());
    int different = 0;
    for (std::size_t i = 0; i < cloud->size(); ++i) different += covariances[i] != on_one_thread[i];
    EXPECT_EQ(different, 0) << threads << " threads give what one gives, bit for bit";
  }
  // A plane's covariance: unit spread in it, 0.001 m^2 across it.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(pcl_covariances[0]);
  EXPECT_NEAR(eig.eigenvalues()[0], 0.001, 1e-9);
  EXPECT_NEAR(eig.eigenvalues()[2], 1.0, 1e-9);
}

TEST(GicpCovariancesTest, FewerPointsThanNeighboursIsRefused) {
  const Cloud::Ptr cloud = RoomCloud(6, 9, false);
  SingleQueryKdTree tree;
  tree.setInputCloud(cloud);
  GicpCovariances covariances(3, Eigen::Matrix3d::Identity());
  EXPECT_FALSE(ComputeGicpCovariances(*cloud, tree, 10, 0.001, 2, &covariances));
  EXPECT_EQ(covariances.size(), 3u) << "left untouched";
}

// The odometry's use: trees built beforehand (GICP told not to rebuild
// them) and both clouds' covariances given; the transformation GICP
// computes with everything of its own, to rounding.
TEST(GicpCovariancesTest, GicpGivenTheCovariancesAlignsAsOnItsOwn) {
  const MovedRoom room = MakeMovedRoom(7, 8, 0.04f, Eigen::Vector3f(-0.1f, 0.2f, 1.0f),
                                       Eigen::Vector3f(-0.15f, 0.1f, 0.02f));
  const Eigen::Matrix4f on_its_own = Align(room, [&](Gicp* gicp) {
    gicp->setSearchMethodTarget(std::make_shared<SingleQueryKdTree>());
    gicp->setSearchMethodSource(std::make_shared<SingleQueryKdTree>());
    gicp->setInputTarget(room.target);
    gicp->setInputSource(room.source);
  });
  const Eigen::Matrix4f given = Align(room, [&](Gicp* gicp) {
    auto target_tree = std::make_shared<SingleQueryKdTree>();
    auto source_tree = std::make_shared<SingleQueryKdTree>();
    gicp->setSearchMethodTarget(target_tree, /*force_no_recompute=*/true);
    gicp->setSearchMethodSource(source_tree, /*force_no_recompute=*/true);
    target_tree->setInputCloud(room.target);
    source_tree->setInputCloud(room.source);
    gicp->setInputTarget(room.target);
    gicp->setInputSource(room.source);
    auto target_covariances = std::make_shared<GicpCovariances>();
    auto source_covariances = std::make_shared<GicpCovariances>();
    ASSERT_TRUE(ComputeGicpCovariances(*room.target, *target_tree, 20, 0.001, 2,
                                       target_covariances.get()));
    ASSERT_TRUE(ComputeGicpCovariances(*room.source, *source_tree, 20, 0.001, 2,
                                       source_covariances.get()));
    gicp->setTargetCovariances(target_covariances);
    gicp->setSourceCovariances(source_covariances);
  });
  EXPECT_LT((given - on_its_own).cwiseAbs().maxCoeff(), 1e-5f) << "rad and m: rounding";
  EXPECT_LT((given * room.motion.matrix() - Eigen::Matrix4f::Identity()).norm(), 0.02f);
}

}  // namespace
}  // namespace tiltcal::calibrate
