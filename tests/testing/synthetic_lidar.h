#ifndef TILTCAL_TESTS_TESTING_SYNTHETIC_LIDAR_H_
#define TILTCAL_TESTS_TESTING_SYNTHETIC_LIDAR_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::testing {

// A ray-cast scene in a "ground" frame g (z up). Planes are n·p + d = 0 and
// are hit from either side; boxes are axis-aligned in g.
struct SyntheticScene {
  bool ground = true;                     // the plane z = 0
  std::vector<Eigen::Vector4d> planes;    // extra planes (walls, ceilings): (n, d)
  std::vector<Eigen::AlignedBox3d> boxes; // obstacles (cars, posts)
};

// A spinning LiDAR with a VLP-16-like beam pattern by default.
struct SyntheticLidar {
  std::vector<double> elevations_deg;     // one per ring
  int azimuth_steps = 1800;               // per revolution
  double sweep_s = 0.1;                   // one revolution
  double range_noise_m = 0.02;            // Gaussian, along the ray
  double max_range_m = 100.0;
  double min_range_m = 0.5;
  static SyntheticLidar Vlp16();
};

// Sensor pose: position in g and orientation R_gl at the stamp; the LiDAR
// turns with a constant body rate omega_lidar_radps (frame l) during the
// sweep: R_gl(t) = R_gl(t_k) Exp(ω (t − t_k)). Point times span
// [−sweep/2, +sweep/2) around the stamp.
struct SyntheticPose {
  Eigen::Vector3d position_g = Eigen::Vector3d(0, 0, 1.0);
  Eigen::Matrix3d g_from_lidar = Eigen::Matrix3d::Identity();
  Eigen::Vector3d omega_lidar_radps = Eigen::Vector3d::Zero();
};

// Ray-casts one sweep into a Scan (x, y, z, intensity, ring, time_offset_ns),
// deterministic for a given seed.
proto::Scan CastScan(const SyntheticScene& scene, const SyntheticLidar& lidar,
                     const SyntheticPose& pose, int64_t stamp_ns, uint32_t seed);

// True ground plane of the pose at the stamp, in the LiDAR frame:
// n_l = R_gl^T e_z, d_l = height of the sensor above z = 0.
Eigen::Vector3d TrueNormal(const SyntheticPose& pose);
double TrueHeight(const SyntheticPose& pose);

// Rotation from roll, pitch, yaw (rad): Rz(yaw) Ry(pitch) Rx(roll).
Eigen::Matrix3d RollPitchYaw(double roll, double pitch, double yaw);

// A street-like scene: ground, two building fronts and parked cars.
SyntheticScene StreetScene(uint32_t seed);

}  // namespace tiltcal::testing

#endif  // TILTCAL_TESTS_TESTING_SYNTHETIC_LIDAR_H_
