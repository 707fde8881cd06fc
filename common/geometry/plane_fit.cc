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

namespace {

// Reassociating float sums lets GCC vectorise the reductions below; NaN and
// infinity semantics are kept (no finite-math), so a NaN point is never
// selected. The order of the vectorised sums is fixed by the binary, so the
// results are deterministic.
#if defined(__GNUC__) && !defined(__clang__)
#define TILTCAL_VECTORISE_SUMS \
  __attribute__((optimize("associative-math", "no-signed-zeros", "no-trapping-math")))
#else
#define TILTCAL_VECTORISE_SUMS
#endif

// SelectAndAccumulate with or without an activity mask.
template <bool kHasActive>
TILTCAL_VECTORISE_SUMS bool SelectAndAccumulateImpl(const float* x, const float* y,
                                                    const float* z, size_t n,
                                                    const uint8_t* active,
                                                    const Eigen::Vector3d& normal, double offset,
                                                    double band, uint8_t* selected,
                                                    PlaneMoments* moments) {
  const Eigen::Vector3d& o = moments->origin();
  // Plane relative to the origin: n·(p − o) + (d + n·o).
  const float nx = static_cast<float>(normal.x()), ny = static_cast<float>(normal.y()),
              nz = static_cast<float>(normal.z());
  const float d_o = static_cast<float>(offset + normal.dot(o));
  const float ox = static_cast<float>(o.x()), oy = static_cast<float>(o.y()),
              oz = static_cast<float>(o.z());
  const float tau = static_cast<float>(band);
  constexpr size_t kBlock = 256;
  uint32_t changed = 0;
  for (size_t begin = 0; begin < n; begin += kBlock) {
    const size_t end = std::min(n, begin + kBlock);
    float c = 0, sx = 0, sy = 0, sz = 0, sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;
    for (size_t k = begin; k < end; ++k) {
      const float px = x[k] - ox, py = y[k] - oy, pz = z[k] - oz;
      const float dist = nx * px + ny * py + nz * pz + d_o;
      uint32_t in = (dist < tau && dist > -tau) ? 1u : 0u;
      if constexpr (kHasActive) in &= active[k] != 0 ? 1u : 0u;
      changed |= in ^ selected[k];
      selected[k] = static_cast<uint8_t>(in);
      const float w = static_cast<float>(in);
      const float wx = w * px, wy = w * py, wz = w * pz;
      c += w;
      sx += wx;
      sy += wy;
      sz += wz;
      sxx += wx * px;
      sxy += wx * py;
      sxz += wx * pz;
      syy += wy * py;
      syz += wy * pz;
      szz += wz * pz;
    }
    const double sums[9] = {sx, sy, sz, sxx, sxy, sxz, syy, syz, szz};
    moments->AddSums(static_cast<int64_t>(std::llround(c)), sums);
  }
  return changed != 0;
}

}  // namespace

bool SelectAndAccumulate(const float* x, const float* y, const float* z, size_t n,
                         const uint8_t* active, const Eigen::Vector3d& normal, double offset,
                         double band, uint8_t* selected, PlaneMoments* moments) {
  return active != nullptr
             ? SelectAndAccumulateImpl<true>(x, y, z, n, active, normal, offset, band, selected,
                                             moments)
             : SelectAndAccumulateImpl<false>(x, y, z, n, active, normal, offset, band, selected,
                                              moments);
}

float MeanOfLowest(const float* v, size_t n, const uint8_t* active, size_t k, float floor) {
  // Candidates below a threshold T; when the buffer is full, keep its k
  // smallest and lower T to the k-th (amortised O(1) per value whatever the
  // order of the values, e.g. a bin whose points come highest first).
  k = std::min<size_t>(std::max<size_t>(k, 1), 64);
  const size_t capacity = 4 * k;
  float buffer[256];
  size_t count = 0;
  float threshold = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < n; ++i) {
    if (active != nullptr && !active[i]) continue;
    const float value = v[i];
    if (!(value >= floor) || !(value < threshold)) continue;
    buffer[count++] = value;
    if (count == capacity) {
      std::nth_element(buffer, buffer + (k - 1), buffer + capacity);
      threshold = buffer[k - 1];
      count = k;
    }
  }
  if (count == 0) return std::numeric_limits<float>::quiet_NaN();
  if (count > k) std::nth_element(buffer, buffer + (k - 1), buffer + count);
  const size_t used = std::min(count, k);
  double sum = 0.0;
  for (size_t j = 0; j < used; ++j) sum += buffer[j];
  return static_cast<float>(sum / static_cast<double>(used));
}

PlaneFit FitPlaneRobust(const float* x, const float* y, const float* z, size_t n,
                        const RobustPlaneOptions& options, std::vector<uint8_t>* inlier) {
  inlier->assign(n, 1);
  if (n == 0) return PlaneFit();
  // Initial fit on all finite points (an infinite band keeps every finite one).
  PlaneMoments all(Eigen::Vector3d(x[0], y[0], z[0]));
  SelectAndAccumulate(x, y, z, n, nullptr, Eigen::Vector3d::UnitZ(), 0.0,
                      std::numeric_limits<double>::infinity(), inlier->data(), &all);
  PlaneFit fit = FitPlane(all, options.min_spread_m2);
  if (!fit.ok) return fit;
  // Band: starts at 3 x the RMS of the initial fit (so a first fit pulled by
  // outliers keeps most points) and halves every round down to
  // inlier_distance_m; converged when the band is at its floor and the inlier
  // set no longer changes. Moments are taken about the initial centroid.
  double tau = std::max(options.inlier_distance_m, 3.0 * std::sqrt(fit.eigenvalues(0)));
  PlaneMoments moments(fit.centroid);
  for (int iter = 0; iter < options.max_iterations && fit.ok; ++iter) {
    moments.Clear();
    const bool at_floor = tau <= options.inlier_distance_m;
    const bool changed = SelectAndAccumulate(x, y, z, n, nullptr, fit.normal, fit.offset, tau,
                                             inlier->data(), &moments);
    if (!changed && at_floor) break;
    if (changed) fit = FitPlane(moments, options.min_spread_m2);
    tau = std::max(options.inlier_distance_m, 0.5 * tau);
  }
  return fit;
}

PlaneFit FitPlaneRobustFrom(const float* x, const float* y, const float* z, size_t n,
                            const Eigen::Vector3d& normal, double offset,
                            const RobustPlaneOptions& options, std::vector<uint8_t>* inlier) {
  inlier->assign(n, 0);
  if (n == 0) return PlaneFit();
  PlaneMoments moments(Eigen::Vector3d(x[0], y[0], z[0]));
  SelectAndAccumulate(x, y, z, n, nullptr, normal, offset, options.inlier_distance_m,
                      inlier->data(), &moments);
  PlaneFit fit = FitPlane(moments, options.min_spread_m2);
  for (int iter = 0; iter < options.max_iterations && fit.ok; ++iter) {
    moments.Clear();
    const bool changed = SelectAndAccumulate(x, y, z, n, nullptr, fit.normal, fit.offset,
                                             options.inlier_distance_m, inlier->data(), &moments);
    if (!changed) break;
    fit = FitPlane(moments, options.min_spread_m2);
  }
  return fit;
}

size_t CountWithinBand(const float* x, const float* y, const float* z, size_t n, size_t stride,
                       const Eigen::Vector3d& normal, double offset, double band) {
  const float nx = static_cast<float>(normal.x()), ny = static_cast<float>(normal.y()),
              nz = static_cast<float>(normal.z()), d = static_cast<float>(offset),
              tau = static_cast<float>(band);
  size_t count = 0;
  stride = std::max<size_t>(stride, 1);
  for (size_t k = 0; k < n; k += stride) {
    const float dist = nx * x[k] + ny * y[k] + nz * z[k] + d;
    count += (dist < tau && dist > -tau) ? 1 : 0;
  }
  return count;
}

}  // namespace tiltcal::geometry
