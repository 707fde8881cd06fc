#include "common/geometry/rotation_statistics.h"

#include "common/geometry/so3.h"

namespace tiltcal::geometry {

RotationStatistics ComputeRotationStatistics(const std::vector<Eigen::Matrix3d>& rotations,
                                             double tolerance_rad, int max_iterations) {
  RotationStatistics stats;
  if (rotations.empty()) return stats;
  const size_t n = rotations.size();
  stats.mean = rotations.front();
  stats.deviations.resize(n);
  for (stats.iterations = 0; stats.iterations < max_iterations; ++stats.iterations) {
    Eigen::Vector3d mean_deviation = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < n; ++i) {
      stats.deviations[i] = LogMatrix(stats.mean.transpose() * rotations[i]);
      mean_deviation += stats.deviations[i];
    }
    mean_deviation /= static_cast<double>(n);
    if (mean_deviation.norm() < tolerance_rad) {
      stats.converged = true;
      break;
    }
    stats.mean = stats.mean * ExpMatrix(mean_deviation);
  }
  if (n > 1) {
    for (const Eigen::Vector3d& xi : stats.deviations) stats.covariance += xi * xi.transpose();
    stats.covariance /= static_cast<double>(n - 1);
  }
  stats.sigma = stats.covariance.diagonal().cwiseSqrt();
  return stats;
}

VectorStatistics ComputeVectorStatistics(const std::vector<Eigen::Vector3d>& vectors) {
  VectorStatistics stats;
  if (vectors.empty()) return stats;
  for (const Eigen::Vector3d& v : vectors) stats.mean += v;
  stats.mean /= static_cast<double>(vectors.size());
  if (vectors.size() > 1) {
    Eigen::Vector3d sum_sq = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& v : vectors) sum_sq += (v - stats.mean).cwiseAbs2();
    stats.sigma = (sum_sq / static_cast<double>(vectors.size() - 1)).cwiseSqrt();
  }
  return stats;
}

}  // namespace tiltcal::geometry
