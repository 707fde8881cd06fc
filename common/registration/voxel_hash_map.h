#ifndef TILTCAL_COMMON_REGISTRATION_VOXEL_HASH_MAP_H_
#define TILTCAL_COMMON_REGISTRATION_VOXEL_HASH_MAP_H_

// A sparse map of points in cubic voxels, keyed by the integer voxel
// coordinates floor(p / voxel_m) in a hash table (KISS-ICP's local map), with
// a plane per voxel for point-to-plane registration.
//
// Each voxel keeps up to max_points_per_voxel points, each at least
// voxel_m / sqrt(max_points_per_voxel) from the others (later ones are
// dropped, so a revisited place or a standing sensor does not grow the map),
// and, once it holds min_plane_points, the PCA plane of its points when that
// plane is thin, sqrt(l3) <= max_plane_thickness_m, and spread in two
// directions, l2 >= min_plane_spread_ratio l1 (covariance eigenvalues
// l1 >= l2 >= l3; a single scan line across a voxel has l2 ~ 0). Planes are
// refitted for the voxels an AddPoints call touched. All coordinates are in
// the map's frame, m. Queries are const and may run on several threads.

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::registration {

// No defaults: every field is set from the params file (calibrate params: lidar_odometry.voxel_icp).
struct VoxelHashMapOptions {
  double voxel_m;  // cube edge, m
  int max_points_per_voxel;
  int min_plane_points;
  double max_plane_thickness_m;  // sqrt(smallest covariance eigenvalue), m
  double min_plane_spread_ratio;  // middle / largest covariance eigenvalue
};

// The nearest map point to a query and the plane of its voxel.
struct PlaneNeighbour {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();     // nearest map point q
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   // unit normal of q's voxel plane
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // mean of that voxel's points
  double distance_m = 0.0;                             // |p - q|
};

// Integer voxel coordinates of p: floor(p / voxel_m) per axis.
Eigen::Vector3i VoxelOf(const Eigen::Vector3d& p, double voxel_m);

// Teschner et al.'s spatial hash of voxel coordinates: a prime per axis, xor.
struct VoxelKeyHash {
  size_t operator()(const Eigen::Vector3i& k) const {
    return static_cast<size_t>(static_cast<uint32_t>(k.x()) * 73856093u ^
                               static_cast<uint32_t>(k.y()) * 19349669u ^
                               static_cast<uint32_t>(k.z()) * 83492791u);
  }
};

class VoxelHashMap {
 public:
  explicit VoxelHashMap(const VoxelHashMapOptions& options);

  // Adds points given in the map frame and refits the touched voxels' planes.
  void AddPoints(const std::vector<Eigen::Vector3d>& points_map);
  // Drops the voxels whose first point lies farther than max_distance_m from
  // `center` (map frame).
  void RemoveFarFrom(const Eigen::Vector3d& center, double max_distance_m);
  // The nearest stored point to p within max_distance_m among the voxels
  // with a plane (searched in every voxel the ball of that radius touches).
  // False when there is none.
  bool FindNearestOnPlane(const Eigen::Vector3d& p, double max_distance_m,
                          PlaneNeighbour* neighbour) const;

  bool empty() const { return voxels_.empty(); }
  size_t num_voxels() const { return voxels_.size(); }
  size_t num_points() const;
  size_t num_planes() const;
  const VoxelHashMapOptions& options() const { return options_; }

 private:
  struct Voxel {
    std::vector<Eigen::Vector3d> points;
    bool has_plane = false;
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  };
  void FitPlane(Voxel* voxel) const;

  VoxelHashMapOptions options_;
  std::unordered_map<Eigen::Vector3i, Voxel, VoxelKeyHash> voxels_;
};

}  // namespace tiltcal::registration

#endif  // TILTCAL_COMMON_REGISTRATION_VOXEL_HASH_MAP_H_
