// SingleQueryKdTree against PCL's own pcl::search::KdTree: the same
// neighbours in the same order with the same distances, and the same GICP
// alignment to the last bit.

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <pcl/common/transforms.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <pcl/search/kdtree.h>

#include "stages/calibrate/single_query_kd_tree.h"

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

TEST(SingleQueryKdTreeTest, GicpAlignsExactlyAsWithPclKdTrees) {
  const Cloud::Ptr target = RoomCloud(3, 4000, false);
  Cloud::Ptr source(new Cloud);
  Eigen::Affine3f motion = Eigen::Affine3f::Identity();
  motion.rotate(Eigen::AngleAxisf(0.05f, Eigen::Vector3f(0.2f, 0.1f, 1.0f).normalized()));
  motion.translation() << 0.2f, -0.1f, 0.05f;
  pcl::transformPointCloud(*RoomCloud(4, 2000, false), *source, motion);

  Eigen::Matrix4f results[2];
  for (int run = 0; run < 2; ++run) {
    pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;
    if (run == 1) {
      gicp.setSearchMethodTarget(std::make_shared<SingleQueryKdTree>());
      gicp.setSearchMethodSource(std::make_shared<SingleQueryKdTree>());
    }
    gicp.setMaxCorrespondenceDistance(1.0);
    gicp.setInputTarget(target);
    gicp.setInputSource(source);
    Cloud aligned;
    gicp.align(aligned);
    ASSERT_TRUE(gicp.hasConverged()) << run;
    results[run] = gicp.getFinalTransformation();
  }
  EXPECT_EQ(results[1], results[0]);
  // It undid the motion.
  EXPECT_LT((results[0] * motion.matrix() - Eigen::Matrix4f::Identity()).norm(), 0.02f);
}

}  // namespace
}  // namespace tiltcal::calibrate
