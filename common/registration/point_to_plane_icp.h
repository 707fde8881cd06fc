#ifndef TILTCAL_COMMON_REGISTRATION_POINT_TO_PLANE_ICP_H_
#define TILTCAL_COMMON_REGISTRATION_POINT_TO_PLANE_ICP_H_

// Point-to-plane ICP of a point set against a VoxelHashMap.
//
// Pose T = (R, t) = map_from_source. A source point p moved to the map,
// p' = R p + t, pairs with its nearest map point (within the gate) whose
// voxel has a plane of unit normal n through the centroid c of the voxel's
// points; the residual is
//   r = n . (p' - c)   (m),
// the distance to that plane (the mean of up to max_points_per_voxel points
// carries less range noise than the nearest point alone).
// The update is a left (map-frame) perturbation delta = (dt, dphi):
//   T <- (Exp(dphi), dt) * T,   i.e. p' <- Exp(dphi) p' + dt,
// so dr/d(dt) = n^T and dr/d(dphi) = (p' x n)^T at delta = 0.
// Each iteration solves the 6x6 normal equations sum w J^T J delta = -sum w J^T r
// with the Geman-McClure weight w = (s^2 / (s^2 + r^2))^2 of kernel scale s,
// and stops when |dphi| and |dt| fall below the convergence thresholds.
// Correspondences are searched on num_threads threads (OpenMP).

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/registration/voxel_hash_map.h"

namespace tiltcal::registration {

// No defaults: every field is set from the params file (calibrate params: lidar_odometry, voxel_icp).
struct PointToPlaneIcpOptions {
  int max_iterations;
  double max_correspondence_m;  // nearest-neighbour gate, m
  double kernel_scale_m;  // Geman-McClure s, m
  double convergence_rotation_rad;
  double convergence_translation_m;
  int min_correspondences;
  int num_threads;
};

struct PointToPlaneIcpResult {
  Eigen::Isometry3d map_from_source = Eigen::Isometry3d::Identity();
  bool registered = false;       // at least min_correspondences and a solvable system
  bool converged = false;        // the last update was below the thresholds
  int iterations = 0;
  // Of the last linearisation (at the pose before the last update, which is
  // below the thresholds when converged): correspondences found, those with
  // |r| <= kernel scale, and the RMS residual of the latter, m.
  int num_correspondences = 0;
  int num_inliers = 0;
  double inlier_rms_m = 0.0;
};

// r = n . (p_map - q) and its Jacobian [n^T, (p_map x n)^T] with respect to
// the left perturbation (dt, dphi) of the pose that produced p_map.
double PointToPlaneResidual(const Eigen::Vector3d& p_map, const Eigen::Vector3d& q,
                            const Eigen::Vector3d& n, Eigen::Matrix<double, 1, 6>* jacobian);

// Aligns `source` (source frame) to `map` starting from `initial`.
PointToPlaneIcpResult AlignPointToPlane(const std::vector<Eigen::Vector3d>& source,
                                        const VoxelHashMap& map,
                                        const Eigen::Isometry3d& initial,
                                        const PointToPlaneIcpOptions& options);

}  // namespace tiltcal::registration

#endif  // TILTCAL_COMMON_REGISTRATION_POINT_TO_PLANE_ICP_H_
