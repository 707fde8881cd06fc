#include "common/registration/point_to_plane_icp.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

#include "common/geometry/so3.h"

namespace tiltcal::registration {
namespace {

// Sums of one pass over the source points at a fixed pose.
struct NormalEquations {
  Eigen::Matrix<double, 6, 6> jtj = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> jtr = Eigen::Matrix<double, 6, 1>::Zero();
  int num_correspondences = 0;
  int num_inliers = 0;
  double inlier_sum_sq_m2 = 0.0;

  void Merge(const NormalEquations& other) {
    jtj += other.jtj;
    jtr += other.jtr;
    num_correspondences += other.num_correspondences;
    num_inliers += other.num_inliers;
    inlier_sum_sq_m2 += other.inlier_sum_sq_m2;
  }
};

NormalEquations Linearise(const std::vector<Eigen::Vector3d>& source, const VoxelHashMap& map,
                          const Eigen::Isometry3d& pose, const PointToPlaneIcpOptions& options) {
  const double s_sq = options.kernel_scale_m * options.kernel_scale_m;
  const int n = static_cast<int>(source.size());
  NormalEquations total;
#pragma omp parallel num_threads(std::max(options.num_threads, 1))
  {
    NormalEquations local;
    PlaneNeighbour neighbour;
    Eigen::Matrix<double, 1, 6> j;
#pragma omp for schedule(static) nowait
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p_map = pose * source[static_cast<size_t>(i)];
      if (!map.FindNearestOnPlane(p_map, options.max_correspondence_m, &neighbour)) continue;
      const double r = PointToPlaneResidual(p_map, neighbour.centroid, neighbour.normal, &j);
      const double r_sq = r * r;
      const double w = (s_sq / (s_sq + r_sq)) * (s_sq / (s_sq + r_sq));
      local.jtj.noalias() += w * j.transpose() * j;
      local.jtr.noalias() += w * r * j.transpose();
      ++local.num_correspondences;
      if (r_sq <= s_sq) {
        ++local.num_inliers;
        local.inlier_sum_sq_m2 += r_sq;
      }
    }
#pragma omp critical
    total.Merge(local);
  }
  return total;
}

void SetStatistics(const NormalEquations& eq, PointToPlaneIcpResult* result) {
  result->num_correspondences = eq.num_correspondences;
  result->num_inliers = eq.num_inliers;
  result->inlier_rms_m = eq.num_inliers > 0 ? std::sqrt(eq.inlier_sum_sq_m2 / eq.num_inliers) : 0.0;
}

}  // namespace

double PointToPlaneResidual(const Eigen::Vector3d& p_map, const Eigen::Vector3d& q,
                            const Eigen::Vector3d& n, Eigen::Matrix<double, 1, 6>* jacobian) {
  if (jacobian != nullptr) {
    jacobian->leftCols<3>() = n.transpose();
    jacobian->rightCols<3>() = p_map.cross(n).transpose();
  }
  return n.dot(p_map - q);
}

PointToPlaneIcpResult AlignPointToPlane(const std::vector<Eigen::Vector3d>& source,
                                        const VoxelHashMap& map,
                                        const Eigen::Isometry3d& initial,
                                        const PointToPlaneIcpOptions& options) {
  PointToPlaneIcpResult result;
  result.map_from_source = initial;
  if (source.empty() || map.empty()) return result;
  for (int iteration = 0; iteration < std::max(options.max_iterations, 1); ++iteration) {
    const NormalEquations eq = Linearise(source, map, result.map_from_source, options);
    SetStatistics(eq, &result);
    if (eq.num_correspondences < std::max(options.min_correspondences, 6)) {
      result.registered = false;
      return result;
    }
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(eq.jtj);
    const Eigen::Matrix<double, 6, 1> delta = ldlt.solve(-eq.jtr);
    if (ldlt.info() != Eigen::Success || !delta.allFinite()) {
      result.registered = false;
      return result;
    }
    Eigen::Isometry3d update = Eigen::Isometry3d::Identity();
    update.linear() = geometry::ExpQuaternion(Eigen::Vector3d(delta.tail<3>())).toRotationMatrix();
    update.translation() = delta.head<3>();
    result.map_from_source = update * result.map_from_source;
    result.iterations = iteration + 1;
    result.registered = true;
    if (delta.tail<3>().norm() < options.convergence_rotation_rad &&
        delta.head<3>().norm() < options.convergence_translation_m) {
      result.converged = true;
      break;
    }
  }
  return result;
}

}  // namespace tiltcal::registration
