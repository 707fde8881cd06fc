#ifndef TILTCAL_TESTS_STAGES_CALIBRATE_SYNTHETIC_ROOM_H_
#define TILTCAL_TESTS_STAGES_CALIBRATE_SYNTHETIC_ROOM_H_

// Test-only ray caster: a box-shaped room (6 inward-facing planes) with
// yaw-rotated boxes and vertical cylinders inside, scanned by a spinning
// multi-beam LiDAR model (VLP-16 like) from given poses. Frame w is the
// scene frame; every surface knows its exact geometry, so tests have truth
// for planes, normals and per-point surface membership.

#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tiltcal::calibrate::testing {

struct OrientedBox {
  Eigen::Vector3d centre;
  Eigen::Vector3d half_extent;
  double yaw_rad = 0.0;  // rotation about z
};

struct VerticalCylinder {
  Eigen::Vector2d centre_xy;
  double radius = 0.2;  // spans the whole room height
};

// A surface of the scene. Planar surfaces satisfy normal^T p + offset = 0
// with the normal pointing out of the solid (into free space).
struct Surface {
  bool planar = true;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
};

struct Scene {
  Eigen::Vector3d room_min;
  Eigen::Vector3d room_max;
  std::vector<OrientedBox> boxes;
  std::vector<VerticalCylinder> cylinders;

  // Surface ids: 0..5 room faces (-x, +x, -y, +y, -z, +z), then 6 per box
  // (box-local -x, +x, -y, +y, -z, +z), then one per cylinder.
  int NumSurfaces() const;
  Surface SurfaceInfo(int id) const;  // planar truth for room/box faces
  bool IsCylinder(int id) const;
  // Distance from p to surface `id` (plane distance, or radial distance for cylinders).
  double DistanceTo(int id, const Eigen::Vector3d& p) const;
  // True when p is within `tolerance` of planar surface `id` and, for a box
  // face, inside the face rectangle (5 cm margin). Box bottoms (on the floor,
  // never visible) and cylinders give false.
  bool OnBoundedSurface(int id, const Eigen::Vector3d& p, double tolerance) const;
  // Surface whose (bounded) geometry is closest to p: a box face counts only
  // within its face rectangle, room faces are infinite planes.
  int NearestSurface(const Eigen::Vector3d& p, double* distance) const;
};

// Room 30 x 12 x 5 m with three boxes and two cylinders; bounds chosen off the
// 0.5 m grid so no plane lies on a voxel boundary.
Scene MakeDefaultScene();

struct Hit {
  double range = 0.0;
  int surface = -1;
};

// First intersection of the ray origin + t dir (t > 0, |dir| = 1).
Hit CastRay(const Scene& scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir);

struct LidarPattern {
  int num_beams = 16;
  double min_elevation_deg = -15.0;
  double max_elevation_deg = 15.0;
  int num_columns = 1800;  // azimuth steps per revolution (0.2 deg for a VLP-16 at 10 Hz)
  double max_range_m = 100.0;
};

struct SimulatedScan {
  std::vector<Eigen::Vector3f> points;  // LiDAR frame
  std::vector<int> surfaces;            // surface id per point
};

// One instantaneous (deskewed) sweep from world_from_lidar, range noise
// N(0, range_sigma_m^2) along each ray.
SimulatedScan ScanScene(const Scene& scene, const Eigen::Isometry3d& world_from_lidar,
                        const LidarPattern& pattern, double range_sigma_m, std::mt19937* rng);

}  // namespace tiltcal::calibrate::testing

#endif  // TILTCAL_TESTS_STAGES_CALIBRATE_SYNTHETIC_ROOM_H_
