#ifndef TILTCAL_COMMON_GEOMETRY_ROTATION_STATISTICS_H_
#define TILTCAL_COMMON_GEOMETRY_ROTATION_STATISTICS_H_

#include <vector>

#include <Eigen/Core>

namespace tiltcal::geometry {

// Spread of a set of rotations C_1..C_N on SO(3), as the repeatability metric
// of the paper (Metrics section):
//   mean     C̄ = argmin_C Σ ||Log(C^T C_i)||²   (Riemannian mean, Manton's
//              fixed-point iteration C̄ <- C̄ Exp(mean_i Log(C̄^T C_i)))
//   ξ_i      = Log(C̄^T C_i)                       (right deviations, rad)
//   Σ        = 1/(N-1) Σ ξ_i ξ_i^T                 (zero for N = 1)
//   σ        = sqrt(diag Σ)
struct RotationStatistics {
  Eigen::Matrix3d mean = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Vector3d> deviations;  // ξ_i, rad
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();  // rad
  int iterations = 0;
  bool converged = false;
};

// Needs at least one rotation. Starts from the first rotation and iterates
// until the mean deviation is below `tolerance_rad`.
RotationStatistics ComputeRotationStatistics(const std::vector<Eigen::Matrix3d>& rotations,
                                             double tolerance_rad = 1e-12,
                                             int max_iterations = 100);

// Mean and per-component sample standard deviation (N-1) of vectors.
struct VectorStatistics {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
};
VectorStatistics ComputeVectorStatistics(const std::vector<Eigen::Vector3d>& vectors);

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_ROTATION_STATISTICS_H_
