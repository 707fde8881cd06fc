#include "stages/ground/scan_plane.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"

namespace tiltcal::ground {

namespace {

using geometry::kDegPerRad;

// Range histograms: 5 cm bins.
constexpr float kRangeBinM = 0.05f;

// Value below which `fraction` of the histogram's samples lie (bin centre).
double HistogramQuantile(const std::vector<uint32_t>& histogram, uint64_t total,
                         double fraction) {
  const uint64_t target = static_cast<uint64_t>(fraction * static_cast<double>(total));
  uint64_t seen = 0;
  for (size_t b = 0; b < histogram.size(); ++b) {
    seen += histogram[b];
    if (seen > target) return (static_cast<double>(b) + 0.5) * kRangeBinM;
  }
  return (static_cast<double>(histogram.size()) - 0.5) * kRangeBinM;
}

}  // namespace

ScanPlaneFitter::ScanPlaneFitter(const proto::ScanPlaneFitParams& plane_fit,
                                 const proto::ScanPlaneGateParams& gates,
                                 const proto::PlaneCovarianceFloorParams& covariance_floor)
    : plane_fit_(plane_fit), gates_(gates), covariance_floor_(covariance_floor) {}

ScanPlane ScanPlaneFitter::Fit(const GroundSegmenter& segmenter,
                               const SegmentationSummary& summary, double height_prior_m,
                               std::vector<uint8_t>* inlier) {
  ScanPlane out;
  inlier->assign(segmenter.num_binned(), 0);
  if (summary.num_binned == 0) {
    out.reason = proto::GROUND_EMPTY_SCAN;
    out.detail = fmt::format("no finite point within {:.1f}..{:.1f} m", segmenter.min_range_m(),
                             segmenter.max_range_m());
    return out;
  }
  num_range_bins_ = static_cast<size_t>(segmenter.max_range_m() / kRangeBinM) + 2;
  out.fit_radius_m = FitRadius(segmenter);
  SelectCandidates(segmenter, out.fit_radius_m);
  out.num_candidates = static_cast<uint32_t>(candidates_.size());
  if (candidates_.size() < gates_.min_inliers()) {
    out.reason = proto::GROUND_TOO_FEW_POINTS;
    out.detail = fmt::format("{} ground points within {:.2f} m, need min_inliers",
                             candidates_.size(), out.fit_radius_m);
    return out;
  }
  out.fit = FitCandidates(segmenter, out.fit_radius_m);
  if (!out.fit.ok) {
    out.reason = proto::GROUND_FIT_FAILED;
    out.detail = fmt::format("degenerate plane from {} points", candidates_.size());
    return out;
  }
  // Sign rule: the normal points towards the sensor (origin), d > 0.
  geometry::OrientTowards(Eigen::Vector3d::Zero(), &out.fit);
  MeasureInliers(segmenter, &out, inlier);
  out.rms_m = std::sqrt(std::max(0.0, out.fit.eigenvalues(0)));
  out.covariance = PlaneCovarianceWithFloors(out.fit, covariance_floor_);
  out.tilt_from_up_deg = std::acos(std::clamp(out.fit.normal.z(), -1.0, 1.0)) * kDegPerRad;
  ApplyScanPlaneGates(gates_, height_prior_m, &out);
  return out;
}

double ScanPlaneFitter::FitRadius(const GroundSegmenter& segmenter) {
  if (plane_fit_.radius_m() > 0.0) return plane_fit_.radius_m();
  // A low quantile of the ground points' ranges: where the lowest beam meets
  // the ground.
  const size_t n = segmenter.num_binned();
  const float* range = segmenter.binned_range();
  const uint8_t* ground = segmenter.binned_ground();
  histogram_.assign(num_range_bins_, 0);
  uint64_t total = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!ground[i]) continue;
    ++histogram_[std::min(num_range_bins_ - 1, static_cast<size_t>(range[i] / kRangeBinM))];
    ++total;
  }
  const double first_ring =
      total > 0 ? HistogramQuantile(histogram_, total, plane_fit_.first_ring_quantile())
                : plane_fit_.radius_min_m();
  return std::clamp(plane_fit_.radius_first_ring_ratio() * first_ring, plane_fit_.radius_min_m(),
                    plane_fit_.radius_max_m());
}

void ScanPlaneFitter::SelectCandidates(const GroundSegmenter& segmenter, double radius_m) {
  const size_t n = segmenter.num_binned();
  const float* x = segmenter.binned_x();
  const float* y = segmenter.binned_y();
  const float* z = segmenter.binned_z();
  const float* range = segmenter.binned_range();
  const uint8_t* ground = segmenter.binned_ground();
  const float radius_f = static_cast<float>(radius_m);
  candidates_.clear();
  cx_.clear();
  cy_.clear();
  cz_.clear();
  for (size_t i = 0; i < n; ++i) {
    if (ground[i] && range[i] <= radius_f) {
      candidates_.push_back(static_cast<uint32_t>(i));
      cx_.push_back(x[i]);
      cy_.push_back(y[i]);
      cz_.push_back(z[i]);
    }
  }
}

// Plane hypotheses: the accepted ground bins near the sensor; the one with
// the most candidates within hypothesis_band_m (scored on at most ~1024
// evenly spaced candidates) is refined with a fixed band, so a kerb or a
// raised sidewalk cannot pull the fit to a compromise. Without hypotheses:
// robust fit from the least-squares plane of all candidates.
geometry::PlaneFit ScanPlaneFitter::FitCandidates(const GroundSegmenter& segmenter,
                                                  double radius_m) {
  geometry::RobustPlaneOptions options;
  options.inlier_distance_m = plane_fit_.inlier_distance_m();
  options.max_iterations = static_cast<int>(plane_fit_.max_iterations());
  segmenter.GroundBinPlanes(radius_m, &hypotheses_);
  const size_t m = cx_.size();
  const size_t stride = std::max<size_t>(1, m / 1024);
  size_t best_score = 0;
  int best = -1;
  for (size_t h = 0; h < hypotheses_.size(); ++h) {
    const Eigen::Vector4d& plane = hypotheses_[h];
    const size_t score =
        geometry::CountWithinBand(cx_.data(), cy_.data(), cz_.data(), m, stride, plane.head<3>(),
                                  plane(3), plane_fit_.hypothesis_band_m());
    if (score > best_score) {
      best_score = score;
      best = static_cast<int>(h);
    }
  }
  if (best >= 0) {
    return geometry::FitPlaneRobustFrom(cx_.data(), cy_.data(), cz_.data(), m,
                                        hypotheses_[best].head<3>(), hypotheses_[best](3),
                                        options, &fit_inlier_);
  }
  return geometry::FitPlaneRobust(cx_.data(), cy_.data(), cz_.data(), m, options, &fit_inlier_);
}

void ScanPlaneFitter::MeasureInliers(const GroundSegmenter& segmenter, ScanPlane* plane,
                                     std::vector<uint8_t>* inlier) {
  const float* x = segmenter.binned_x();
  const float* y = segmenter.binned_y();
  const float* range = segmenter.binned_range();
  uint32_t num_inliers = 0;
  const uint32_t sectors = gates_.azimuth_sectors();
  sector_count_.assign(sectors, 0);
  histogram_.assign(num_range_bins_, 0);
  const float sector_scale = static_cast<float>(sectors / (2.0 * M_PI));
  for (size_t k = 0; k < candidates_.size(); ++k) {
    if (!fit_inlier_[k]) continue;
    const uint32_t i = candidates_[k];
    (*inlier)[i] = 1;
    ++num_inliers;
    const uint32_t s = std::min<uint32_t>(
        static_cast<uint32_t>(Azimuth02Pi(y[i], x[i]) * sector_scale), sectors - 1);
    ++sector_count_[s];
    ++histogram_[std::min(num_range_bins_ - 1, static_cast<size_t>(range[i] / kRangeBinM))];
  }
  plane->num_inliers = num_inliers;
  // Radial spread of the inliers: 90th / 10th percentile of the ranges
  // (5 cm resolution).
  if (num_inliers >= 10) {
    const double r_lo = HistogramQuantile(histogram_, num_inliers, 0.1);
    const double r_hi = HistogramQuantile(histogram_, num_inliers, 0.9);
    plane->radial_spread = r_lo > 0.0 ? r_hi / r_lo : 0.0;
  }
  uint32_t covered = 0;
  for (uint32_t c : sector_count_) covered += c >= gates_.min_points_per_sector() ? 1 : 0;
  plane->coverage = static_cast<double>(covered) / sectors;
}

Eigen::Matrix4d PlaneCovarianceWithFloors(const geometry::PlaneFit& fit,
                                          const proto::PlaneCovarianceFloorParams& floor) {
  Eigen::Matrix4d covariance =
      geometry::PlaneCovariance(fit, geometry::PlaneNoiseVariance(fit));
  const double floor_rad = geometry::DegToRad(floor.normal_deg());
  covariance.topLeftCorner<3, 3>() +=
      floor_rad * floor_rad * (Eigen::Matrix3d::Identity() - fit.normal * fit.normal.transpose());
  covariance(3, 3) += floor.height_m() * floor.height_m();
  return covariance;
}

void ApplyScanPlaneGates(const proto::ScanPlaneGateParams& gates, double height_prior_m,
                         ScanPlane* plane) {
  const double height = plane->fit.offset;
  if (plane->num_inliers < gates.min_inliers()) {
    plane->reason = proto::GROUND_TOO_FEW_POINTS;
    plane->detail =
        fmt::format("{} inliers < min_inliers {}", plane->num_inliers, gates.min_inliers());
  } else if (!(height > 0.0)) {
    plane->reason = proto::GROUND_FIT_FAILED;
    plane->detail = fmt::format("plane through the sensor (d = {:.3f} m)", height);
  } else if (plane->tilt_from_up_deg > gates.max_normal_tilt_deg()) {
    plane->reason = proto::GROUND_NORMAL_NOT_UP;
    plane->detail = fmt::format("normal {:.2f} deg from up > {:.2f} deg", plane->tilt_from_up_deg,
                                gates.max_normal_tilt_deg());
  } else if (plane->coverage < gates.min_azimuth_coverage()) {
    plane->reason = proto::GROUND_POOR_COVERAGE;
    plane->detail = fmt::format("azimuth coverage {:.3f} < {:.3f}", plane->coverage,
                                gates.min_azimuth_coverage());
  } else if (plane->radial_spread < gates.min_radial_spread_ratio()) {
    plane->reason = proto::GROUND_POOR_COVERAGE;
    plane->detail = fmt::format("radial spread {:.3f} < {:.3f} (ground seen by a single beam?)",
                                plane->radial_spread, gates.min_radial_spread_ratio());
  } else if (plane->rms_m > gates.max_rms_m()) {
    plane->reason = proto::GROUND_HIGH_RMS;
    plane->detail = fmt::format("rms {:.4f} m > {:.4f} m", plane->rms_m, gates.max_rms_m());
  } else if (height_prior_m > 0.0 &&
             std::fabs(height - height_prior_m) > gates.max_height_deviation_m()) {
    plane->reason = proto::GROUND_HEIGHT_PRIOR;
    plane->detail = fmt::format("height {:.3f} m vs prior {:.3f} m", height, height_prior_m);
  }
}

void ApplyTiltJumpGate(const proto::TiltJumpGateParams& gate,
                       std::vector<proto::GroundPlane>* planes) {
  const double max_jump_deg = gate.max_jump_deg();
  const int window = static_cast<int>(gate.window());
  const int n = static_cast<int>(planes->size());
  std::vector<Eigen::Vector3d> normals(n, Eigen::Vector3d::Zero());
  std::vector<bool> valid(n, false);
  for (int i = 0; i < n; ++i) {
    const proto::GroundPlane& p = (*planes)[i];
    valid[i] = p.valid();
    normals[i] = ToEigen(p.normal_in_lidar());
  }
  // Decisions use the validity before this pass only.
  for (int i = 0; i < n; ++i) {
    if (!valid[i]) continue;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    for (int j = std::max(0, i - window); j <= std::min(n - 1, i + window); ++j) {
      if (j == i || !valid[j]) continue;
      sum += normals[j];
      ++count;
    }
    if (count < 2 || !(sum.norm() > 0.0)) continue;
    const double cos_angle = std::clamp(sum.normalized().dot(normals[i]), -1.0, 1.0);
    const double jump_deg = std::acos(cos_angle) * kDegPerRad;
    proto::GroundPlane& p = (*planes)[i];
    p.set_tilt_jump_deg(jump_deg);
    if (max_jump_deg > 0.0 && jump_deg > max_jump_deg) {
      p.set_valid(false);
      p.set_reject_reason(proto::GROUND_TILT_JUMP);
      p.set_reject_detail(fmt::format("normal {:.2f} deg from its neighbours' mean > {:.2f} deg",
                                      jump_deg, max_jump_deg));
    }
  }
}

}  // namespace tiltcal::ground
