#include "stages/calibrate/problem/surfel_map.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "common/geometry/angles.h"
#include "stages/calibrate/problem/point_priority.h"

namespace tiltcal::calibrate {
namespace {

// 21 bits per axis, two's complement: cells in [-2^20, 2^20).
constexpr int kKeyBits = 21;
constexpr std::uint64_t kKeyMask = (std::uint64_t{1} << kKeyBits) - 1;

}  // namespace

// The PCA plane of moments taken relative to the voxel centre: centroid
// relative to the centre, covariance eigenvalues descending (l1, l2, l3) and
// the eigenvector of l3 (geometry::FitPlane returns them ascending; the sign
// of the normal is set by MakeSurfel). ok = false when FitPlane finds no
// plane (points on a line or a spot: l2 < 1e-5 l1).
struct SurfelMap::PcaResult {
  bool ok = false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d eigenvalues = Eigen::Vector3d::Zero();  // descending, m^2
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

SurfelMap::PcaResult SurfelMap::FitPca(const geometry::PlaneMoments& moments) {
  const geometry::PlaneFit fit = geometry::FitPlane(moments, /*min_spread_m2=*/0.0);
  PcaResult r;
  r.ok = fit.ok;
  r.mean = fit.centroid;
  r.eigenvalues = fit.eigenvalues.reverse();
  r.normal = fit.normal;
  return r;
}

SurfelMap::SurfelMap(const proto::SurfelMapParams& params)
    : params_(params), voxel_m_(params.voxel_m()) {}

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
  const Eigen::Vector3d s = p_a / voxel_m_;
  return Eigen::Vector3i(static_cast<int>(std::floor(s.x())), static_cast<int>(std::floor(s.y())),
                         static_cast<int>(std::floor(s.z())));
}

Eigen::Vector3d SurfelMap::Centre(const Eigen::Vector3i& v) const {
  return (v.cast<double>() + Eigen::Vector3d::Constant(0.5)) * voxel_m_;
}

void SurfelMap::Accumulate(const Eigen::Vector3d& p_a, const Eigen::Vector3d* sensor_a) {
  if (!p_a.allFinite()) return;
  const Eigen::Vector3i v = VoxelOf(p_a);
  VoxelStats& stats = voxels_[Key(v)];
  const Eigen::Vector3d centre = Centre(v);
  if (stats.moments.count() == 0) stats.voxel = v;
  const Eigen::Vector3d q = p_a - centre;
  const int cap = static_cast<int>(params_.sample_points());
  const int count = static_cast<int>(stats.moments.count());
  if (cap > 0 && count % stats.sample_stride == 0) {
    if (static_cast<int>(stats.sample.size()) >= cap) {
      // Keep positions 0, 2, 4, ... = points 0, 2s, 4s, ...; double the stride.
      std::size_t kept = 0;
      for (std::size_t i = 0; i < stats.sample.size(); i += 2) stats.sample[kept++] = stats.sample[i];
      stats.sample.resize(kept);
      stats.sample_stride *= 2;
    }
    if (count % stats.sample_stride == 0) stats.sample.push_back(q.cast<float>());
  }
  stats.moments.Add(q.x(), q.y(), q.z());
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

SurfelMap::SampleCheck SurfelMap::CheckSampleOutliers(const std::vector<Eigen::Vector3f>& sample,
                                                      PcaResult* pca, int* fit_count,
                                                      bool* refitted) const {
  // Outlier check on the sample, refit on its inliers when some are off
  // (two rounds). Inlier gate: 3 robust sigmas of the sample residuals
  // (1.4826 MAD), clamped to [min_inlier_distance_m, inlier_distance_m].
  const double min_gate = params_.min_inlier_distance_m();
  const double max_gate = std::max(params_.inlier_distance_m(), min_gate);
  const int n_sample = static_cast<int>(sample.size());
  for (int round = 0; round < 2 && n_sample > 0; ++round) {
    std::vector<double> residuals;
    residuals.reserve(sample.size());
    for (const Eigen::Vector3f& qf : sample) {
      residuals.push_back(std::abs(pca->normal.dot(qf.cast<double>() - pca->mean)));
    }
    std::vector<double> sorted = residuals;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2),
                     sorted.end());
    const double robust_sigma = 1.4826 * sorted[sorted.size() / 2];
    const double gate = std::clamp(3.0 * robust_sigma, min_gate, max_gate);
    int inliers = 0;
    geometry::PlaneMoments inlier_moments;  // relative to the voxel centre, like the sample
    for (std::size_t i = 0; i < sample.size(); ++i) {
      if (residuals[i] > gate) continue;
      const Eigen::Vector3d q = sample[i].cast<double>();
      ++inliers;
      inlier_moments.Add(q.x(), q.y(), q.z());
    }
    if (inliers < params_.min_inlier_fraction() * n_sample || inliers < 3) {
      return SampleCheck::kOutliers;
    }
    if (inliers == n_sample) break;
    *pca = FitPca(inlier_moments);
    if (!pca->ok) return SampleCheck::kDegenerate;
    *fit_count = inliers;
    if (round == 0) *refitted = true;
  }
  return SampleCheck::kAccepted;
}

bool SurfelMap::PassesPlanarityGate(const PcaResult& pca, int fit_count,
                                    SurfelExtractionSummary* summary,
                                    double* normal_sigma_rad) const {
  const double l1 = pca.eigenvalues(0), l2 = pca.eigenvalues(1), l3 = pca.eigenvalues(2);
  if (!(l2 > 0.0) || l2 < params_.min_spread_ratio() * l1) {
    ++summary->rejected_line_like;
    return false;
  }
  if (l3 > params_.max_planarity() * l2) {
    ++summary->rejected_not_flat;
    return false;
  }
  if (l3 > params_.max_thickness_m() * params_.max_thickness_m()) {
    ++summary->rejected_too_thick;
    return false;
  }
  *normal_sigma_rad = std::sqrt(l3 / (fit_count * l2));
  if (*normal_sigma_rad > geometry::DegToRad(params_.max_normal_sigma_deg())) {
    ++summary->rejected_uncertain_normal;
    return false;
  }
  return true;
}

Surfel SurfelMap::MakeSurfel(const VoxelStats& stats, const PcaResult& pca,
                             double normal_sigma_rad) const {
  Surfel surfel;
  surfel.voxel = stats.voxel;
  surfel.num_points = static_cast<int>(stats.moments.count());
  surfel.eigenvalues_m2 = pca.eigenvalues;
  surfel.normal_sigma_rad = normal_sigma_rad;
  const Eigen::Vector3d centre = Centre(stats.voxel);
  surfel.centroid = centre + pca.mean;
  surfel.normal = pca.normal;
  // Orient towards the mean sensor origin when known, else make the sign
  // deterministic: largest component > 0.
  if (stats.num_with_sensor > 0) {
    const Eigen::Vector3d to_sensor =
        centre + stats.sum_sensor / stats.num_with_sensor - surfel.centroid;
    if (surfel.normal.dot(to_sensor) < 0.0) surfel.normal = -surfel.normal;
  } else {
    Eigen::Index largest = 0;
    surfel.normal.cwiseAbs().maxCoeff(&largest);
    if (surfel.normal(largest) < 0.0) surfel.normal = -surfel.normal;
  }
  surfel.offset_m = -surfel.normal.dot(surfel.centroid);
  return surfel;
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

  const int64_t min_points = std::max<int64_t>(params_.min_points(), 3);
  for (const std::uint64_t key : keys) {
    const VoxelStats& stats = voxels_.at(key);
    if (stats.moments.count() < min_points) {
      ++summary.rejected_too_few_points;
      continue;
    }
    PcaResult pca = FitPca(stats.moments);
    if (!pca.ok) {
      ++summary.rejected_line_like;
      continue;
    }
    int fit_count = static_cast<int>(stats.moments.count());
    bool refitted = false;
    const SampleCheck check = CheckSampleOutliers(stats.sample, &pca, &fit_count, &refitted);
    if (refitted) ++summary.refitted;
    if (check == SampleCheck::kOutliers) {
      ++summary.rejected_outliers;
      continue;
    }
    if (check == SampleCheck::kDegenerate) {
      ++summary.rejected_line_like;
      continue;
    }
    double normal_sigma_rad = 0.0;
    if (!PassesPlanarityGate(pca, fit_count, &summary, &normal_sigma_rad)) continue;
    surfel_of_voxel_[key] = static_cast<int>(surfels_.size());
    surfels_.push_back(MakeSurfel(stats, pca, normal_sigma_rad));
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
                                                    const proto::AssociationParams& params,
                                                    const std::vector<uint64_t>& priorities) const {
  assert(priorities.empty() || priorities.size() == points_a.size());
  const double max_centroid_distance = params.max_centroid_distance_factor() * voxel_m_;
  // Candidates grouped per surfel, each group in increasing point order.
  std::unordered_map<int, std::vector<SurfelAssociation>> per_surfel;
  std::vector<int> surfel_order;  // first-seen order, for a deterministic output
  for (std::size_t i = 0; i < points_a.size(); ++i) {
    const Eigen::Vector3d& p = points_a[i];
    const int s = SurfelIndexAt(p);
    if (s < 0) continue;
    const Surfel& surfel = surfels_[static_cast<std::size_t>(s)];
    const double distance = surfel.normal.dot(p) + surfel.offset_m;
    if (std::abs(distance) > params.max_distance_m()) continue;
    if ((p - surfel.centroid).norm() > max_centroid_distance) continue;
    auto [it, inserted] = per_surfel.try_emplace(s);
    if (inserted) surfel_order.push_back(s);
    it->second.push_back(SurfelAssociation{static_cast<int>(i), s, distance});
  }
  std::vector<SurfelAssociation> out;
  for (const int s : surfel_order) {
    const std::vector<SurfelAssociation>& group = per_surfel.at(s);
    const std::size_t n = group.size();
    const std::size_t cap =
        std::max<std::size_t>(params.max_points_per_surfel_per_scan(), 1);
    if (n <= cap) {
      out.insert(out.end(), group.begin(), group.end());
    } else if (!priorities.empty()) {
      std::vector<SurfelAssociation> lowest = group;
      KeepLowestPriority(
          cap,
          [&](const SurfelAssociation& a) { return priorities[static_cast<std::size_t>(a.point_index)]; },
          &lowest);
      out.insert(out.end(), lowest.begin(), lowest.end());
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
