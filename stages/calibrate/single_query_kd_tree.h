#ifndef TILTCAL_STAGES_CALIBRATE_SINGLE_QUERY_KD_TREE_H_
#define TILTCAL_STAGES_CALIBRATE_SINGLE_QUERY_KD_TREE_H_

// The k-d tree of PCL's GICP (its target and source neighbour searches)
// without an OpenMP parallel region per query.
//
// pcl::search::KdTree answers each query through FLANN's batch search, which
// opens `#pragma omp parallel num_threads(cores)` even for a single point.
// In Debian's libpcl_kdtree, built with OpenMP, entering and leaving that
// region took ~40 % of the GICP odometry's CPU samples
// (stages/calibrate/README.md, "Speed"). SingleQueryKdTree is a
// pcl::search::KdTree, so GICP's setSearchMethodTarget and
// setSearchMethodSource take it, and its queries go to a pcl::KdTreeFLANN
// instantiated in this library, which is compiled without OpenMP. It is the
// same tree (FLANN's single-index k-d tree, 15 points per leaf, invalid
// points left out), the same exact search and the same sorting, so it gives
// the same neighbours in the same order as pcl::search::KdTree.

#include <vector>

#include <flann/algorithms/dist.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

namespace tiltcal::calibrate {

// FLANN's L2_Simple<float> under a name of its own: the FLANN and
// KdTreeFLANN templates instantiated for it here are not libpcl_kdtree's.
struct SingleQueryL2 : flann::L2_Simple<float> {};

}  // namespace tiltcal::calibrate

// Instantiated once, in single_query_kd_tree.cc.
extern template class pcl::KdTreeFLANN<pcl::PointXYZ, tiltcal::calibrate::SingleQueryL2>;

namespace tiltcal::calibrate {

class SingleQueryKdTree final : public pcl::search::KdTree<pcl::PointXYZ> {
 public:
  using Base = pcl::search::KdTree<pcl::PointXYZ>;
  using Base::nearestKSearch;
  using Base::radiusSearch;

  explicit SingleQueryKdTree(bool sorted = true);

  void setSortedResults(bool sorted) override;
  void setInputCloud(const PointCloudConstPtr& cloud,
                     const pcl::IndicesConstPtr& indices = pcl::IndicesConstPtr()) override;
  // Squared distances, m^2; sorted by distance when sorted results are set.
  int nearestKSearch(const pcl::PointXYZ& point, int k, pcl::Indices& k_indices,
                     std::vector<float>& k_sqr_distances) const override;
  int radiusSearch(const pcl::PointXYZ& point, double radius, pcl::Indices& k_indices,
                   std::vector<float>& k_sqr_distances, unsigned int max_nn = 0) const override;

 private:
  pcl::KdTreeFLANN<pcl::PointXYZ, SingleQueryL2> tree_without_openmp_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_SINGLE_QUERY_KD_TREE_H_
