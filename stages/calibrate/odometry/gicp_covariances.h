#ifndef TILTCAL_STAGES_CALIBRATE_ODOMETRY_GICP_COVARIANCES_H_
#define TILTCAL_STAGES_CALIBRATE_ODOMETRY_GICP_COVARIANCES_H_

// The point covariances of GICP (Segal, Haehnel and Thrun, "Generalized-ICP",
// 2009), computed on several threads. For each point p_i of a cloud:
//   S_i = 1/k sum_j q_j q_j^T - m m^T,   m = 1/k sum_j q_j,
// over its k nearest neighbours q_j in the cloud (p_i itself included),
// and S_i = U diag(1, 1, epsilon) U^T with U the singular vectors of S_i
// (largest first): a plane of unit spread with epsilon across it (m^2).
// Since S_i is symmetric positive semi-definite, U holds its eigenvectors
// and U diag(1, 1, epsilon) U^T = I - (1 - epsilon) n n^T with n the
// eigenvector of the smallest eigenvalue, computed in closed form
// (Eigen's SelfAdjointEigenSolver::computeDirect).
//
// PCL's GICP computes the same covariances on one thread with a JacobiSVD
// per point (with the k-nearest-neighbour search, 57 % of the odometry's
// CPU; the SVD alone 6 % of the whole stage's): the two agree to ~1e-13,
// and GICP given these covariances returns its own transformation to
// rounding (stages/calibrate/README.md, "Speed").

#include <vector>

#include <Eigen/Core>
#include <Eigen/StdVector>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

namespace tiltcal::calibrate {

using GicpCovariances = std::vector<Eigen::Matrix3d, Eigen::aligned_allocator<Eigen::Matrix3d>>;

// `tree` holds `cloud` (its neighbour searches must be safe to run
// concurrently: pcl::KdTreeFLANN's are). False (and *covariances untouched)
// when the cloud has fewer than k points; PCL then refuses too.
bool ComputeGicpCovariances(const pcl::PointCloud<pcl::PointXYZ>& cloud,
                            const pcl::search::KdTree<pcl::PointXYZ>& tree, int k,
                            double epsilon, int num_threads, GicpCovariances* covariances);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_ODOMETRY_GICP_COVARIANCES_H_
