#include "common/registration/voxel_downsample.h"

#include <unordered_set>

#include "common/registration/voxel_hash_map.h"

namespace tiltcal::registration {

std::vector<Eigen::Vector3d> VoxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                             double voxel_m) {
  if (!(voxel_m > 0.0)) return points;
  std::unordered_set<Eigen::Vector3i, VoxelKeyHash> occupied;
  occupied.reserve(points.size());
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(points.size() / 4);
  for (const Eigen::Vector3d& p : points) {
    if (occupied.insert(VoxelOf(p, voxel_m)).second) kept.push_back(p);
  }
  return kept;
}

}  // namespace tiltcal::registration
