#include "stages/calibrate/odometry/single_query_kd_tree.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <nanoflann.hpp>

namespace tiltcal::calibrate {

namespace {

// nanoflann's view of the packed x, y, z floats.
struct PackedPoints {
  const std::vector<float>* xyz;
  size_t kdtree_get_point_count() const { return xyz->size() / 3; }
  float kdtree_get_pt(size_t i, size_t dim) const { return (*xyz)[3 * i + dim]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox&) const {
    return false;  // nanoflann computes it
  }
};

// Squared Euclidean distance in float, summed over x, y, z in that order
// (FLANN's L2_Simple<float>).
// Indices are pcl::index_t, so searches write straight into pcl::Indices.
using Metric = nanoflann::L2_Simple_Adaptor<float, PackedPoints, float, pcl::index_t>;

// Points per leaf (FLANN's single-index tree in PCL: 15).
constexpr size_t kLeafSize = 15;

}  // namespace

struct SingleQueryKdTree::Index {
  explicit Index(const std::vector<float>* xyz)
      : points{xyz}, tree(3, points, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize)) {}
  PackedPoints points;
  nanoflann::KDTreeSingleIndexAdaptor<Metric, PackedPoints, 3, pcl::index_t> tree;
};

SingleQueryKdTree::SingleQueryKdTree(bool sorted) : Base(sorted) {}

SingleQueryKdTree::~SingleQueryKdTree() = default;

void SingleQueryKdTree::setInputCloud(const PointCloudConstPtr& cloud,
                                      const pcl::IndicesConstPtr& indices) {
  input_ = cloud;
  indices_ = indices;
  index_.reset();
  xyz_.clear();
  cloud_index_.clear();
  if (cloud == nullptr) return;
  auto add = [&](int i) {
    const pcl::PointXYZ& p = (*cloud)[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) return;
    xyz_.insert(xyz_.end(), {p.x, p.y, p.z});
    cloud_index_.push_back(i);
  };
  const size_t n = indices != nullptr ? indices->size() : cloud->size();
  xyz_.reserve(3 * n);
  cloud_index_.reserve(n);
  for (size_t j = 0; j < n; ++j) add(indices != nullptr ? (*indices)[j] : static_cast<int>(j));
  if (!cloud_index_.empty()) index_ = std::make_unique<Index>(&xyz_);
}

int SingleQueryKdTree::nearestKSearch(const pcl::PointXYZ& point, int k, pcl::Indices& k_indices,
                                      std::vector<float>& k_sqr_distances) const {
  // cloud_index_ is empty when there is no tree.
  const size_t wanted = std::min<size_t>(std::max(k, 0), cloud_index_.size());
  k_indices.resize(wanted);
  k_sqr_distances.resize(wanted);
  if (wanted == 0) return 0;
  const float query[3] = {point.x, point.y, point.z};
  const size_t n = index_->tree.knnSearch(query, wanted, k_indices.data(), k_sqr_distances.data());
  k_indices.resize(n);
  k_sqr_distances.resize(n);
  for (pcl::index_t& i : k_indices) i = cloud_index_[i];  // tree order -> cloud index
  return static_cast<int>(n);
}

int SingleQueryKdTree::radiusSearch(const pcl::PointXYZ& point, double radius,
                                    pcl::Indices& k_indices, std::vector<float>& k_sqr_distances,
                                    unsigned int max_nn) const {
  k_indices.clear();
  k_sqr_distances.clear();
  if (index_ == nullptr) return 0;
  const float query[3] = {point.x, point.y, point.z};
  std::vector<std::pair<pcl::index_t, float>> matches;
  index_->tree.radiusSearch(query, static_cast<float>(radius * radius), matches,
                            nanoflann::SearchParams(32, 0.0f, /*sorted=*/true));
  if (max_nn > 0 && matches.size() > max_nn) matches.resize(max_nn);
  k_indices.reserve(matches.size());
  k_sqr_distances.reserve(matches.size());
  for (const auto& [i, d] : matches) {
    k_indices.push_back(cloud_index_[i]);
    k_sqr_distances.push_back(d);
  }
  return static_cast<int>(matches.size());
}

}  // namespace tiltcal::calibrate
