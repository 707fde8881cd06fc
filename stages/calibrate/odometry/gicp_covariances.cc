#include "stages/calibrate/odometry/gicp_covariances.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <thread>

namespace tiltcal::calibrate {
namespace {

// Points [begin, end) of the cloud; see the header for the formula.
void CovariancesOfRange(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                        const pcl::search::KdTree<pcl::PointXYZ>& tree, int k, double epsilon,
                        std::size_t begin, std::size_t end, GicpCovariances* out) {
  pcl::Indices neighbours;
  std::vector<float> squared_distances;
  neighbours.reserve(static_cast<std::size_t>(k));
  squared_distances.reserve(static_cast<std::size_t>(k));
  for (std::size_t i = begin; i < end; ++i) {
    tree.nearestKSearch(cloud[i], k, neighbours, squared_distances);
    // Lower triangle of the second moment and the mean, summed in double.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
    for (int j = 0; j < k; ++j) {
      const pcl::PointXYZ& q = cloud[static_cast<std::size_t>(neighbours[static_cast<std::size_t>(j)])];
      mean[0] += q.x;
      mean[1] += q.y;
      mean[2] += q.z;
      s(0, 0) += q.x * q.x;
      s(1, 0) += q.y * q.x;
      s(1, 1) += q.y * q.y;
      s(2, 0) += q.z * q.x;
      s(2, 1) += q.z * q.y;
      s(2, 2) += q.z * q.z;
    }
    mean /= static_cast<double>(k);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c <= r; ++c) {
        s(r, c) /= static_cast<double>(k);
        s(r, c) -= mean[r] * mean[c];
        s(c, r) = s(r, c);
      }
    }
    // U diag(1, 1, epsilon) U^T = I - (1 - epsilon) n n^T, n the eigenvector
    // of S's smallest eigenvalue (S is symmetric positive semi-definite, so
    // its singular vectors are its eigenvectors).
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(s, Eigen::ComputeEigenvectors);
    const Eigen::Vector3d n = eigen.eigenvectors().col(0);
    (*out)[i] = Eigen::Matrix3d::Identity() - (1.0 - epsilon) * n * n.transpose();
  }
}

}  // namespace

bool ComputeGicpCovariances(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                            const pcl::search::KdTree<pcl::PointXYZ>& tree, int k,
                            double epsilon, int num_threads, GicpCovariances* covariances) {
  const std::size_t n = cloud.size();
  if (k <= 0 || static_cast<std::size_t>(k) > n) return false;
  covariances->resize(n);
  // Below a few hundred points a thread costs more than it saves.
  constexpr std::size_t kMinPointsPerThread = 256;
  const std::size_t threads = std::clamp<std::size_t>(
      std::min<std::size_t>(static_cast<std::size_t>(std::max(num_threads, 1)),
                            n / kMinPointsPerThread),
      1, 64);
  std::vector<std::thread> workers;
  const std::size_t chunk = (n + threads - 1) / threads;
  for (std::size_t t = 1; t < threads; ++t) {
    const std::size_t begin = std::min(n, t * chunk);
    const std::size_t end = std::min(n, begin + chunk);
    workers.emplace_back(CovariancesOfRange, std::cref(cloud), std::cref(tree), k, epsilon, begin,
                         end, covariances);
  }
  CovariancesOfRange(cloud, tree, k, epsilon, 0, std::min(n, chunk), covariances);
  for (std::thread& w : workers) w.join();
  return true;
}

}  // namespace tiltcal::calibrate
