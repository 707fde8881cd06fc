#include "stages/calibrate/single_query_kd_tree.h"

// The KdTreeFLANN template's definitions, instantiated here for
// SingleQueryL2 in a library compiled without OpenMP (the omp pragmas of
// FLANN's headers are then ignored).
#include <pcl/kdtree/impl/kdtree_flann.hpp>

#ifdef _OPENMP
#error "single_query_kd_tree.cc must be compiled without OpenMP (single_query_kd_tree.h)"
#endif

template class pcl::KdTreeFLANN<pcl::PointXYZ, tiltcal::calibrate::SingleQueryL2>;

namespace tiltcal::calibrate {

SingleQueryKdTree::SingleQueryKdTree(bool sorted) : Base(sorted), tree_without_openmp_(sorted) {}

void SingleQueryKdTree::setSortedResults(bool sorted) {
  Base::setSortedResults(sorted);
  tree_without_openmp_.setSortedResults(sorted);
}

void SingleQueryKdTree::setInputCloud(const PointCloudConstPtr& cloud,
                                      const pcl::IndicesConstPtr& indices) {
  tree_without_openmp_.setInputCloud(cloud, indices);
  input_ = cloud;
  indices_ = indices;
}

int SingleQueryKdTree::nearestKSearch(const pcl::PointXYZ& point, int k, pcl::Indices& k_indices,
                                      std::vector<float>& k_sqr_distances) const {
  return tree_without_openmp_.nearestKSearch(point, k, k_indices, k_sqr_distances);
}

int SingleQueryKdTree::radiusSearch(const pcl::PointXYZ& point, double radius,
                                    pcl::Indices& k_indices, std::vector<float>& k_sqr_distances,
                                    unsigned int max_nn) const {
  return tree_without_openmp_.radiusSearch(point, radius, k_indices, k_sqr_distances, max_nn);
}

}  // namespace tiltcal::calibrate
