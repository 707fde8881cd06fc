#ifndef TILTCAL_STAGES_CALIBRATE_ODOMETRY_SINGLE_QUERY_KD_TREE_H_
#define TILTCAL_STAGES_CALIBRATE_ODOMETRY_SINGLE_QUERY_KD_TREE_H_

// The k-d tree of PCL's GICP (its target and source neighbour searches) and
// of the GICP covariances (gicp_covariances.h): a pcl::search::KdTree, so
// GICP's setSearchMethodTarget and setSearchMethodSource take it, whose
// queries go to a nanoflann k-d tree over the cloud's finite points.
//
// pcl::search::KdTree answers each query through FLANN's batch search, which
// opens `#pragma omp parallel num_threads(cores)` even for a single point
// (in Debian's libpcl_kdtree, built with OpenMP, ~40 % of the GICP
// odometry's CPU samples); FLANN's single-index tree without that region was
// still ~25 % of the stage's CPU (stages/calibrate/README.md, "Speed").
// The searches are exact and the distances are computed as FLANN's
// L2_Simple<float> does (the sum of (q_i - p_i)^2 over x, y, z in float), so
// the neighbours, their order and their squared distances are those of
// pcl::search::KdTree, except which of several points at exactly the same
// distance comes first.

#include <memory>
#include <vector>

#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

namespace tiltcal::calibrate {

class SingleQueryKdTree final : public pcl::search::KdTree<pcl::PointXYZ> {
 public:
  using Base = pcl::search::KdTree<pcl::PointXYZ>;
  using Base::nearestKSearch;
  using Base::radiusSearch;

  explicit SingleQueryKdTree(bool sorted = true);
  ~SingleQueryKdTree() override;

  void setInputCloud(const PointCloudConstPtr& cloud,
                     const pcl::IndicesConstPtr& indices = pcl::IndicesConstPtr()) override;
  // The k nearest (all when fewer), sorted by distance; squared distances,
  // m^2. Safe to call from several threads at once.
  int nearestKSearch(const pcl::PointXYZ& point, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;
  // The points within `radius` (m), the max_nn nearest of them when max_nn
  // > 0, sorted by distance.
  int radiusSearch(const pcl::PointXYZ& point, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override;

 private:
  struct Index;
  // x, y, z of the finite points of the cloud (of `indices` when given), in
  // their order, and each one's index in the cloud.
  std::vector<float> xyz_;
  std::vector<int> cloud_index_;
  std::unique_ptr<Index> index_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_ODOMETRY_SINGLE_QUERY_KD_TREE_H_
