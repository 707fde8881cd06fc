#include "stages/calibrate/surfel_map.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace tiltcal::calibrate {
namespace {

// 21 bits per axis, two's complement: cells in [-2^20, 2^20).
constexpr int kKeyBits = 21;
constexpr std::uint64_t kKeyMask = (std::uint64_t{1} << kKeyBits) - 1;

// Plane fit by PCA of voxel moments (local, as common/geometry has no plane
// fit helper yet). Input: count n, sum s and sum of outer products S of the
// points relative to some reference c. Output: centroid (relative to c),
// covariance eigenvalues descending and the eigenvector of the smallest.
struct PcaResult {
  Eigen::Vector3d mean;
  Eigen::Vector3d eigenvalues;  // descending
  Eigen::Vector3d normal;       // eigenvector of eigenvalues(2)
};

PcaResult PcaFromMoments(int n, const Eigen::Vector3d& sum, const Eigen::Matrix3d& sum_outer) {
  PcaResult r;
  r.mean = sum / n;
  // Cov = S/n - mean mean^T (population covariance).
  Eigen::Matrix3d cov = sum_outer / n - r.mean * r.mean.transpose();
  cov = 0.5 * (cov + cov.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov);
  const Eigen::Vector3d ascending = solver.eigenvalues().cwiseMax(0.0);
  r.eigenvalues = Eigen::Vector3d(ascending(2), ascending(1), ascending(0));
  r.normal = solver.eigenvectors().col(0).normalized();
  return r;
}

}  // namespace

SurfelMap::SurfelMap(const SurfelMapOptions& options) : options_(options) {}

std::uint64_t SurfelMap::Key(const Eigen::Vector3i& v) {
  // Offset by 2^20 so the packed key orders like (x, y, z) lexicographically
  // with x in the most significant bits.
  const std::uint64_t offset = std::uint64_t{1} << (kKeyBits - 1);
  const std::uint64_t x = (static_cast<std::uint64_t>(static_cast<std::int64_t>(v.x())) + offset) & kKeyMask;
  const std::uint64_t y = (static_cast<std::uint64_t>(static_cast<std::int64_t>(v.y())) + offset) & kKeyMask;
  const std::uint64_t z = (static_cast<std::uint64_t>(static_cast<std::int64_t>(v.z())) + offset) & kKeyMask;
  return (x << (2 * kKeyBits)) | (y << kKeyBits) | z;
}

Eigen::Vector3i SurfelMap::VoxelOf(const Eigen::Vector3d& p_a) const {
  const Eigen::Vector3d s = p_a / options_.voxel_size_m;
  return Eigen::Vector3i(static_cast<int>(std::floor(s.x())), static_cast<int>(std::floor(s.y())),
                         static_cast<int>(std::floor(s.z())));
}

Eigen::Vector3d SurfelMap::Centre(const Eigen::Vector3i& v) const {
  return (v.cast<double>() + Eigen::Vector3d::Constant(0.5)) * options_.voxel_size_m;
}

void SurfelMap::Accumulate(const Eigen::Vector3d& p_a, const Eigen::Vector3d* sensor_a) {
  if (!p_a.allFinite()) return;
  const Eigen::Vector3i v = VoxelOf(p_a);
  VoxelStats& stats = voxels_[Key(v)];
  const Eigen::Vector3d centre = Centre(v);
  if (stats.count == 0) stats.voxel = v;
  const Eigen::Vector3d q = p_a - centre;
  const int cap = std::max(options_.sample_points_per_voxel, 0);
  if (cap > 0 && stats.count % stats.sample_stride == 0) {
    if (static_cast<int>(stats.sample.size()) >= cap) {
      // Keep positions 0, 2, 4, ... = points 0, 2s, 4s, ...; double the stride.
      std::size_t kept = 0;
      for (std::size_t i = 0; i < stats.sample.size(); i += 2) stats.sample[kept++] = stats.sample[i];
      stats.sample.resize(kept);
      stats.sample_stride *= 2;
    }
    if (stats.count % stats.sample_stride == 0) stats.sample.push_back(q.cast<float>());
  }
  ++stats.count;
  stats.sum += q;
  stats.sum_outer.noalias() += q * q.transpose();
  if (sensor_a != nullptr) {
    ++stats.num_with_sensor;
    stats.sum_sensor += *sensor_a - centre;
  }
}

void SurfelMap::AddPoints(const Eigen::Isometry3d& a_from_lidar,
                          const std::vector<Eigen::Vector3f>& points_lidar) {
  const Eigen::Vector3d sensor = a_from_lidar.translation();
  for (const Eigen::Vector3f& p : points_lidar) {
    Accumulate(a_from_lidar * p.cast<double>(), &sensor);
  }
}

void SurfelMap::AddPointsInWorld(const std::vector<Eigen::Vector3d>& points_a) {
  for (const Eigen::Vector3d& p : points_a) Accumulate(p, nullptr);
}

SurfelExtractionSummary SurfelMap::ExtractSurfels() {
  SurfelExtractionSummary summary;
  surfels_.clear();
  surfel_of_voxel_.clear();
  std::vector<std::uint64_t> keys;
  keys.reserve(voxels_.size());
  for (const auto& [key, stats] : voxels_) keys.push_back(key);
  std::sort(keys.begin(), keys.end());
  summary.num_voxels = static_cast<int>(keys.size());

  const double max_thickness_sq = options_.max_thickness_m * options_.max_thickness_m;
  for (const std::uint64_t key : keys) {
    const VoxelStats& stats = voxels_.at(key);
    if (stats.count < std::max(options_.min_points, 3)) {
      ++summary.rejected_too_few_points;
      continue;
    }
    PcaResult pca = PcaFromMoments(stats.count, stats.sum, stats.sum_outer);
    int fit_count = stats.count;
    // Outlier check on the sample, refit on its inliers when some are off
    // (two rounds). Inlier gate: 3 robust sigmas of the sample residuals
    // (1.4826 MAD), clamped to [min_inlier_distance_m, inlier_distance_m].
    bool rejected = false;
    for (int round = 0; round < 2 && !stats.sample.empty(); ++round) {
      std::vector<double> residuals;
      residuals.reserve(stats.sample.size());
      for (const Eigen::Vector3f& qf : stats.sample) {
        residuals.push_back(std::abs(pca.normal.dot(qf.cast<double>() - pca.mean)));
      }
      std::vector<double> sorted = residuals;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
      const double robust_sigma = 1.4826 * sorted[sorted.size() / 2];
      const double gate = std::clamp(3.0 * robust_sigma, options_.min_inlier_distance_m,
                                     std::max(options_.inlier_distance_m, options_.min_inlier_distance_m));
      int inliers = 0;
      Eigen::Vector3d in_sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d in_outer = Eigen::Matrix3d::Zero();
      for (std::size_t i = 0; i < stats.sample.size(); ++i) {
        if (residuals[i] > gate) continue;
        const Eigen::Vector3d q = stats.sample[i].cast<double>();
        ++inliers;
        in_sum += q;
        in_outer.noalias() += q * q.transpose();
      }
      const int n_sample = static_cast<int>(stats.sample.size());
      if (inliers < options_.min_inlier_fraction * n_sample || inliers < 3) {
        rejected = true;
        break;
      }
      if (inliers == n_sample) break;
      pca = PcaFromMoments(inliers, in_sum, in_outer);
      fit_count = inliers;
      if (round == 0) ++summary.refitted;
    }
    if (rejected) {
      ++summary.rejected_outliers;
      continue;
    }
    const double l1 = pca.eigenvalues(0), l2 = pca.eigenvalues(1), l3 = pca.eigenvalues(2);
    if (!(l2 > 0.0) || l2 < options_.min_spread_ratio * l1) {
      ++summary.rejected_line_like;
      continue;
    }
    if (l3 > options_.max_eigen_ratio * l2) {
      ++summary.rejected_not_flat;
      continue;
    }
    if (l3 > max_thickness_sq) {
      ++summary.rejected_too_thick;
      continue;
    }
    const double normal_sigma = std::sqrt(l3 / (fit_count * l2));
    if (normal_sigma > options_.max_normal_sigma_rad) {
      ++summary.rejected_uncertain_normal;
      continue;
    }
    Surfel surfel;
    surfel.voxel = stats.voxel;
    surfel.num_points = stats.count;
    surfel.eigenvalues_m2 = pca.eigenvalues;
    surfel.normal_sigma_rad = normal_sigma;
    const Eigen::Vector3d centre = Centre(stats.voxel);
    surfel.centroid = centre + pca.mean;
    surfel.normal = pca.normal;
    // Orient towards the mean sensor origin when known, else keep the
    // eigenvector sign made deterministic by its largest component > 0.
    if (stats.num_with_sensor > 0) {
      const Eigen::Vector3d to_sensor = centre + stats.sum_sensor / stats.num_with_sensor - surfel.centroid;
      if (surfel.normal.dot(to_sensor) < 0.0) surfel.normal = -surfel.normal;
    } else {
      Eigen::Index largest = 0;
      surfel.normal.cwiseAbs().maxCoeff(&largest);
      if (surfel.normal(largest) < 0.0) surfel.normal = -surfel.normal;
    }
    surfel.offset_m = -surfel.normal.dot(surfel.centroid);
    surfel_of_voxel_[key] = static_cast<int>(surfels_.size());
    surfels_.push_back(surfel);
  }
  summary.num_surfels = static_cast<int>(surfels_.size());
  return summary;
}

int SurfelMap::SurfelIndexAt(const Eigen::Vector3d& p_a) const {
  if (!p_a.allFinite()) return -1;
  const auto it = surfel_of_voxel_.find(Key(VoxelOf(p_a)));
  return it == surfel_of_voxel_.end() ? -1 : it->second;
}

std::vector<SurfelAssociation> SurfelMap::Associate(const std::vector<Eigen::Vector3d>& points_a,
                                                    const AssociationOptions& options) const {
  const int stride = std::max(options.point_stride, 1);
  const double max_centroid_distance = options.max_centroid_distance_factor * options_.voxel_size_m;
  // Candidates grouped per surfel, each group in increasing point order.
  std::unordered_map<int, std::vector<SurfelAssociation>> per_surfel;
  std::vector<int> surfel_order;  // first-seen order, for a deterministic output
  for (std::size_t i = 0; i < points_a.size(); i += static_cast<std::size_t>(stride)) {
    const Eigen::Vector3d& p = points_a[i];
    const int s = SurfelIndexAt(p);
    if (s < 0) continue;
    const Surfel& surfel = surfels_[static_cast<std::size_t>(s)];
    const double distance = surfel.normal.dot(p) + surfel.offset_m;
    if (std::abs(distance) > options.max_distance_m) continue;
    if ((p - surfel.centroid).norm() > max_centroid_distance) continue;
    auto [it, inserted] = per_surfel.try_emplace(s);
    if (inserted) surfel_order.push_back(s);
    it->second.push_back(SurfelAssociation{static_cast<int>(i), s, distance});
  }
  std::vector<SurfelAssociation> out;
  for (const int s : surfel_order) {
    const std::vector<SurfelAssociation>& group = per_surfel.at(s);
    const std::size_t n = group.size();
    const std::size_t cap = options.max_points_per_surfel > 0
                                ? static_cast<std::size_t>(options.max_points_per_surfel)
                                : n;
    if (n <= cap) {
      out.insert(out.end(), group.begin(), group.end());
    } else {
      // cap evenly spaced picks: index floor((k + 0.5) * n / cap), k = 0..cap-1.
      for (std::size_t k = 0; k < cap; ++k) {
        out.push_back(group[(2 * k + 1) * n / (2 * cap)]);
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const SurfelAssociation& a, const SurfelAssociation& b) {
    return a.point_index < b.point_index;
  });
  return out;
}

}  // namespace tiltcal::calibrate
