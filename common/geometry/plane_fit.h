#ifndef TILTCAL_COMMON_GEOMETRY_PLANE_FIT_H_
#define TILTCAL_COMMON_GEOMETRY_PLANE_FIT_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace tiltcal::geometry {

// First and second moments of a 3D point set, accumulated in double relative
// to a fixed `origin` (choose a point near the set to avoid cancellation).
class PlaneMoments {
 public:
  PlaneMoments() = default;
  explicit PlaneMoments(const Eigen::Vector3d& origin) : origin_(origin) {}

  void Add(double x, double y, double z) {
    const double dx = x - origin_.x(), dy = y - origin_.y(), dz = z - origin_.z();
    ++count_;
    sx_ += dx; sy_ += dy; sz_ += dz;
    sxx_ += dx * dx; sxy_ += dx * dy; sxz_ += dx * dz;
    syy_ += dy * dy; syz_ += dy * dz; szz_ += dz * dz;
  }
  void Clear() { *this = PlaneMoments(origin_); }
  // Adds the sums of `count` points taken relative to origin():
  // sums = {Σx, Σy, Σz, Σxx, Σxy, Σxz, Σyy, Σyz, Σzz}.
  void AddSums(int64_t count, const double sums[9]) {
    count_ += count;
    sx_ += sums[0]; sy_ += sums[1]; sz_ += sums[2];
    sxx_ += sums[3]; sxy_ += sums[4]; sxz_ += sums[5];
    syy_ += sums[6]; syz_ += sums[7]; szz_ += sums[8];
  }

  int64_t count() const { return count_; }
  const Eigen::Vector3d& origin() const { return origin_; }
  // Mean of the points; origin when empty.
  Eigen::Vector3d Mean() const;
  // Covariance normalised by N (the scatter matrix / N), m^2; zero when empty.
  Eigen::Matrix3d Covariance() const;

 private:
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  int64_t count_ = 0;
  double sx_ = 0, sy_ = 0, sz_ = 0;
  double sxx_ = 0, sxy_ = 0, sxz_ = 0, syy_ = 0, syz_ = 0, szz_ = 0;
};

// A least-squares (PCA) plane n·p + offset = 0.
struct PlaneFit {
  bool ok = false;                    // false: fewer than 3 points, degenerate or non-finite
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit; sign as oriented
  double offset = 0.0;                // d of n·p + d = 0 (= −n·centroid)
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  // Eigenvalues of the covariance (normalised by N), ascending, m^2;
  // eigenvalues(0) is the mean squared distance of the points to the plane.
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();
  // Matching unit eigenvectors (columns); column 0 is the normal.
  Eigen::Matrix3d eigenvectors = Eigen::Matrix3d::Identity();
  int64_t num_points = 0;
};

// PCA plane of the accumulated points. The fit fails (ok = false) with fewer
// than 3 points, with a non-finite covariance, or when the middle eigenvalue
// is below `min_spread_m2` or below 1e-5 x the largest (points on a line or a
// single spot). The normal is
// oriented with a non-negative z component (callers re-orient as needed).
PlaneFit FitPlane(const PlaneMoments& moments, double min_spread_m2 = 1e-8);

// Flips the plane so that `viewpoint` lies on its positive side
// (n·viewpoint + d >= 0), e.g. a ground normal pointing towards the sensor.
void OrientTowards(const Eigen::Vector3d& viewpoint, PlaneFit* plane);

// Unbiased estimate of the point noise variance along the normal (m^2):
// N λ_min / (N − 3); 0 for N <= 3.
double PlaneNoiseVariance(const PlaneFit& plane);

// First-order covariance of (n_x, n_y, n_z, d) of a PCA plane fit to N points
// with isotropic noise of variance `noise_variance_m2` along the normal:
//   Cov(n)    = σ²/N · Σ_{k=mid,max} v_k v_kᵀ / λ_k
//   Var(d)    = cᵀ Cov(n) c + σ²/N
//   Cov(n, d) = −Cov(n) c
// (d = −n·c; the centroid error along n is uncorrelated with δn). Zero when
// the plane is not ok.
Eigen::Matrix4d PlaneCovariance(const PlaneFit& plane, double noise_variance_m2);

// One pass of inlier selection over contiguous columns: point k is selected
// when active[k] (all when active == nullptr) and |n·p_k + d| < band; the
// selection is written to selected[k] and the selected points are added to
// `moments` (relative to its origin). Returns true when any selected[k]
// changed. Branch-free, in float blocks of 256 points summed in double, so the
// compiler vectorises it; accurate to ~1e-7 relative for points within a few
// hundred metres of the moments' origin.
bool SelectAndAccumulate(const float* x, const float* y, const float* z, size_t n,
                         const uint8_t* active, const Eigen::Vector3d& normal, double offset,
                         double band, uint8_t* selected, PlaneMoments* moments);

// Mean of the `k` smallest values of v[0..n) (all of them when n <= k), in
// one pass without reordering; only values >= floor count (NaN when none).
// `active` (optional) masks values out.
float MeanOfLowest(const float* v, size_t n, const uint8_t* active, size_t k, float floor);

// Options of FitPlaneRobust.
struct RobustPlaneOptions {
  double inlier_distance_m;     // inliers: |n·p + d| < this; no default (params)
  int max_iterations;           // refits after the initial fit; no default (params)
  double min_spread_m2 = 1e-8;  // see FitPlane
};

// Plane through the points 0..n−1 of the columns (x, y, z): an initial PCA
// fit on all finite points, then up to max_iterations rounds of re-selecting
// inliers |n·p + d| < band and refitting on them. The band starts at 3 x the
// RMS of the initial fit and halves every round down to inlier_distance_m; the
// loop stops early once the band is at that floor and the inlier set no
// longer changes. `inlier` (resized to n) receives 1 for the points used by
// the returned fit. Never allocates beyond `inlier`.
PlaneFit FitPlaneRobust(const float* x, const float* y, const float* z, size_t n,
                        const RobustPlaneOptions& options, std::vector<uint8_t>* inlier);

// As FitPlaneRobust, but starting from the plane n·p + d = 0 (unit n) with
// the band at inlier_distance_m from the first round: a refinement of a
// hypothesis that must not drift to a compromise between nearby surfaces.
PlaneFit FitPlaneRobustFrom(const float* x, const float* y, const float* z, size_t n,
                            const Eigen::Vector3d& normal, double offset,
                            const RobustPlaneOptions& options, std::vector<uint8_t>* inlier);

// Number of the points k = 0, stride, 2·stride, ... < n with |n·p + d| < band.
size_t CountWithinBand(const float* x, const float* y, const float* z, size_t n, size_t stride,
                       const Eigen::Vector3d& normal, double offset, double band);

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_PLANE_FIT_H_
