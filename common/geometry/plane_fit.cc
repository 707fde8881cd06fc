#include "common/geometry/plane_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

namespace tiltcal::geometry {

Eigen::Vector3d PlaneMoments::Mean() const {
  if (count_ == 0) return origin_;
  const double inv = 1.0 / static_cast<double>(count_);
  return origin_ + Eigen::Vector3d(sx_ * inv, sy_ * inv, sz_ * inv);
}

Eigen::Matrix3d PlaneMoments::Covariance() const {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  if (count_ == 0) return cov;
  const double inv = 1.0 / static_cast<double>(count_);
  const double mx = sx_ * inv, my = sy_ * inv, mz = sz_ * inv;
  cov(0, 0) = sxx_ * inv - mx * mx;
  cov(0, 1) = sxy_ * inv - mx * my;
  cov(0, 2) = sxz_ * inv - mx * mz;
  cov(1, 1) = syy_ * inv - my * my;
  cov(1, 2) = syz_ * inv - my * mz;
  cov(2, 2) = szz_ * inv - mz * mz;
  cov(1, 0) = cov(0, 1);
  cov(2, 0) = cov(0, 2);
  cov(2, 1) = cov(1, 2);
  return cov;
}

PlaneFit FitPlane(const PlaneMoments& moments, double min_spread_m2) {
  PlaneFit fit;
  fit.num_points = moments.count();
  if (moments.count() < 3) return fit;
  fit.centroid = moments.Mean();
  const Eigen::Matrix3d cov = moments.Covariance();
  if (!cov.allFinite() || !fit.centroid.allFinite()) return fit;
  // Closed-form 3x3 symmetric solver; eigenvalues come out ascending. It is
  // accurate to ~1e-7 relative to the largest eigenvalue; when the smallest
  // eigenvalue is far below that, one iteration of the general solver would
  // be needed, but the moments are taken about a nearby origin so the
  // relative accuracy is sufficient for plane normals.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(cov);
  if (solver.info() != Eigen::Success) return fit;
  Eigen::Vector3d eigenvalues = solver.eigenvalues().cwiseMax(0.0);
  Eigen::Matrix3d vectors = solver.eigenvectors();
  if (!eigenvalues.allFinite() || !vectors.allFinite()) return fit;
  // Points on a line or a spot: the normal is undetermined. The relative
  // bound also covers the closed-form solver's rounding on exact lines.
  if (eigenvalues(1) < min_spread_m2 || eigenvalues(1) < 1e-5 * eigenvalues(2)) return fit;
  Eigen::Vector3d normal = vectors.col(0);
  const double norm = normal.norm();
  if (!(norm > 0.5)) return fit;
  normal /= norm;
  if (normal.z() < 0.0) normal = -normal;
  vectors.col(0) = normal;
  fit.normal = normal;
  fit.offset = -normal.dot(fit.centroid);
  fit.eigenvalues = eigenvalues;
  fit.eigenvectors = vectors;
  fit.ok = std::isfinite(fit.offset);
  return fit;
}

void OrientTowards(const Eigen::Vector3d& viewpoint, PlaneFit* plane) {
  if (plane->normal.dot(viewpoint) + plane->offset < 0.0) {
    plane->normal = -plane->normal;
    plane->offset = -plane->offset;
    plane->eigenvectors.col(0) = plane->normal;
  }
}

double PlaneNoiseVariance(const PlaneFit& plane) {
  if (plane.num_points <= 3) return 0.0;
  const double n = static_cast<double>(plane.num_points);
  return n * plane.eigenvalues(0) / (n - 3.0);
}

Eigen::Matrix4d PlaneCovariance(const PlaneFit& plane, double noise_variance_m2) {
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
  if (!plane.ok || plane.num_points < 3) return cov;
  const double n = static_cast<double>(plane.num_points);
  const double s2n = noise_variance_m2 / n;
  Eigen::Matrix3d cov_n = Eigen::Matrix3d::Zero();
  for (int k = 1; k < 3; ++k) {
    const Eigen::Vector3d v = plane.eigenvectors.col(k);
    cov_n += v * v.transpose() * (s2n / plane.eigenvalues(k));
  }
  const Eigen::Vector3d cov_nd = -cov_n * plane.centroid;
  cov.topLeftCorner<3, 3>() = cov_n;
  cov.topRightCorner<3, 1>() = cov_nd;
  cov.bottomLeftCorner<1, 3>() = cov_nd.transpose();
  cov(3, 3) = plane.centroid.dot(cov_n * plane.centroid) + s2n;
  if (!cov.allFinite()) return Eigen::Matrix4d::Zero();
  return cov;
}

PlaneFit FitPlaneRobust(const float* x, const float* y, const float* z, const uint32_t* idx,
                        size_t n, const RobustPlaneOptions& options,
                        std::vector<uint8_t>* inlier) {
  inlier->assign(n, 1);
  if (n == 0) return PlaneFit();
  const uint32_t i0 = idx != nullptr ? idx[0] : 0;
  PlaneMoments moments(Eigen::Vector3d(x[i0], y[i0], z[i0]));
  for (size_t k = 0; k < n; ++k) {
    const uint32_t i = idx != nullptr ? idx[k] : static_cast<uint32_t>(k);
    moments.Add(x[i], y[i], z[i]);
  }
  PlaneFit fit = FitPlane(moments, options.min_spread_m2);
  // Band: starts at 3 x the RMS of the initial fit (so a first fit pulled by
  // outliers keeps most points) and halves every round down to
  // inlier_distance_m; converged when the band is at its floor and the inlier
  // set no longer changes.
  double tau = std::max(options.inlier_distance_m,
                        3.0 * std::sqrt(std::max(0.0, fit.eigenvalues(0))));
  for (int iter = 0; iter < options.max_iterations && fit.ok; ++iter) {
    moments.Clear();
    const double nx = fit.normal.x(), ny = fit.normal.y(), nz = fit.normal.z();
    const double d = fit.offset;
    const bool at_floor = tau <= options.inlier_distance_m;
    bool changed = false;
    uint8_t* mask = inlier->data();
    for (size_t k = 0; k < n; ++k) {
      const uint32_t i = idx != nullptr ? idx[k] : static_cast<uint32_t>(k);
      const double dist = nx * x[i] + ny * y[i] + nz * z[i] + d;
      const uint8_t in = std::fabs(dist) < tau ? 1 : 0;
      changed |= (in != mask[k]);
      mask[k] = in;
      if (in) moments.Add(x[i], y[i], z[i]);
    }
    if (!changed && at_floor) break;
    if (changed) fit = FitPlane(moments, options.min_spread_m2);
    tau = std::max(options.inlier_distance_m, 0.5 * tau);
  }
  return fit;
}

}  // namespace tiltcal::geometry
