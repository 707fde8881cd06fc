#include "common/registration/voxel_hash_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/geometry/plane_fit.h"

namespace tiltcal::registration {

Eigen::Vector3i VoxelOf(const Eigen::Vector3d& p, double voxel_m) {
  return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / voxel_m)),
                         static_cast<int>(std::floor(p.y() / voxel_m)),
                         static_cast<int>(std::floor(p.z() / voxel_m)));
}

VoxelHashMap::VoxelHashMap(const VoxelHashMapOptions& options) : options_(options) {}

size_t VoxelHashMap::num_points() const {
  size_t n = 0;
  for (const auto& [key, voxel] : voxels_) n += voxel.points.size();
  return n;
}

size_t VoxelHashMap::num_planes() const {
  size_t n = 0;
  for (const auto& [key, voxel] : voxels_) n += voxel.has_plane ? 1 : 0;
  return n;
}

void VoxelHashMap::FitPlane(Voxel* voxel) const {
  voxel->has_plane = false;
  if (static_cast<int>(voxel->points.size()) < options_.min_plane_points) return;
  geometry::PlaneMoments moments(voxel->points.front());
  for (const Eigen::Vector3d& p : voxel->points) moments.Add(p.x(), p.y(), p.z());
  const geometry::PlaneFit plane = geometry::FitPlane(moments);
  if (!plane.ok) return;
  const double thickness_m = std::sqrt(std::max(plane.eigenvalues(0), 0.0));
  if (thickness_m > options_.max_plane_thickness_m) return;
  if (plane.eigenvalues(1) < options_.min_plane_spread_ratio * plane.eigenvalues(2)) return;
  voxel->normal = plane.normal;
  voxel->centroid = plane.centroid;
  voxel->has_plane = true;
}

void VoxelHashMap::AddPoints(const std::vector<Eigen::Vector3d>& points_map) {
  const size_t max_points = static_cast<size_t>(std::max(options_.max_points_per_voxel, 1));
  const double min_spacing_sq = options_.voxel_m * options_.voxel_m / static_cast<double>(max_points);
  std::vector<Voxel*> touched;
  for (const Eigen::Vector3d& p : points_map) {
    Voxel& voxel = voxels_[VoxelOf(p, options_.voxel_m)];
    if (voxel.points.size() >= max_points) continue;
    const bool too_close = std::any_of(voxel.points.begin(), voxel.points.end(),
                                       [&](const Eigen::Vector3d& q) {
                                         return (q - p).squaredNorm() < min_spacing_sq;
                                       });
    if (too_close) continue;
    if (voxel.points.empty()) voxel.points.reserve(max_points);
    voxel.points.push_back(p);
    if (touched.empty() || touched.back() != &voxel) touched.push_back(&voxel);
  }
  // References to unordered_map elements survive rehashing; each touched
  // voxel is refitted once.
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  for (Voxel* voxel : touched) FitPlane(voxel);
}

void VoxelHashMap::RemoveFarFrom(const Eigen::Vector3d& center, double max_distance_m) {
  const double max_sq = max_distance_m * max_distance_m;
  for (auto it = voxels_.begin(); it != voxels_.end();) {
    if ((it->second.points.front() - center).squaredNorm() > max_sq) {
      it = voxels_.erase(it);
    } else {
      ++it;
    }
  }
}

bool VoxelHashMap::FindNearestOnPlane(const Eigen::Vector3d& p, double max_distance_m,
                                      PlaneNeighbour* neighbour) const {
  // Only the voxels that the ball of radius max_distance_m around p touches
  // (at most 27 when max_distance_m <= voxel_m).
  const Eigen::Vector3i low = VoxelOf(p - Eigen::Vector3d::Constant(max_distance_m), options_.voxel_m);
  const Eigen::Vector3i high =
      VoxelOf(p + Eigen::Vector3d::Constant(max_distance_m), options_.voxel_m);
  double best_sq = max_distance_m * max_distance_m;
  const Voxel* best_voxel = nullptr;
  const Eigen::Vector3d* best_point = nullptr;
  Eigen::Vector3i key;
  for (key.x() = low.x(); key.x() <= high.x(); ++key.x()) {
    for (key.y() = low.y(); key.y() <= high.y(); ++key.y()) {
      for (key.z() = low.z(); key.z() <= high.z(); ++key.z()) {
        const auto it = voxels_.find(key);
        if (it == voxels_.end() || !it->second.has_plane) continue;
        for (const Eigen::Vector3d& q : it->second.points) {
          const double d_sq = (q - p).squaredNorm();
          if (d_sq < best_sq) {
            best_sq = d_sq;
            best_voxel = &it->second;
            best_point = &q;
          }
        }
      }
    }
  }
  if (best_voxel == nullptr) return false;
  neighbour->point = *best_point;
  neighbour->normal = best_voxel->normal;
  neighbour->centroid = best_voxel->centroid;
  neighbour->distance_m = std::sqrt(best_sq);
  return true;
}

}  // namespace tiltcal::registration
