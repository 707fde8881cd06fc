#include "stages/ground/ground_segmentation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/geometry/angles.h"
#include "common/geometry/plane_fit.h"

namespace tiltcal::ground {

namespace {

using geometry::kRadPerDeg;
constexpr float kTwoPi = 6.28318530717958647692f;

}  // namespace

void ZoneBoundaries(const proto::ZoneModelParams& zone_model, double bound_m[5]) {
  const double lo = zone_model.min_range_m(), hi = zone_model.max_range_m();
  bound_m[0] = lo;
  bound_m[4] = hi;
  if (zone_model.boundaries_m_size() == 3) {
    for (int k = 0; k < 3; ++k) bound_m[k + 1] = zone_model.boundaries_m(k);
  } else {
    bound_m[1] = (7.0 * lo + hi) / 8.0;
    bound_m[2] = (3.0 * lo + hi) / 4.0;
    bound_m[3] = (lo + hi) / 2.0;
  }
}

float Azimuth02Pi(float y, float x) {
  const float ax = std::fabs(x), ay = std::fabs(y);
  const float mx = std::max(ax, ay), mn = std::min(ax, ay);
  if (!(mx > 0.0f)) return 0.0f;
  const float a = mn / mx;
  const float s = a * a;
  // Minimax polynomial for atan on [0, 1], |error| < 1e-5 rad.
  float r = ((-0.0464964749f * s + 0.15931422f) * s - 0.327622764f) * s * a + a;
  if (ay > ax) r = 1.57079632679f - r;
  if (x < 0.0f) r = 3.14159265359f - r;
  if (y < 0.0f) r = kTwoPi - r;
  return r >= kTwoPi ? 0.0f : r;
}

GroundSegmenter::GroundSegmenter(const proto::ZoneModelParams& zone_model,
                                 const proto::RegionFitParams& region_fit) {
  ZoneBoundaries(zone_model, bound_);
  num_rings_ = 0;
  num_bins_ = 0;
  for (int k = 0; k < 4; ++k) {
    rings_[k] = static_cast<int>(zone_model.rings(k));
    sectors_[k] = static_cast<int>(zone_model.sectors(k));
    inv_ring_width_[k] = rings_[k] / (bound_[k + 1] - bound_[k]);
    sector_scale_[k] = static_cast<float>(sectors_[k] / (2.0 * M_PI));
    first_ring_[k] = num_rings_;
    for (int r = 0; r < rings_[k]; ++r) {
      ring_first_bin_.push_back(num_bins_);
      num_bins_ += sectors_[k];
    }
    num_rings_ += rings_[k];
  }
  ring_first_bin_.push_back(num_bins_);
  num_iterations_ = static_cast<int>(region_fit.num_iterations());
  num_seed_points_ = region_fit.num_seed_points();
  seed_margin_ = static_cast<float>(region_fit.seed_height_margin_m());
  plane_distance_ = static_cast<float>(region_fit.plane_distance_m());
  min_points_per_bin_ = std::max<uint32_t>(3, region_fit.min_points_per_bin());
  cos_max_tilt_ = static_cast<float>(std::cos(region_fit.max_bin_tilt_deg() * kRadPerDeg));
  max_flatness_ = static_cast<float>(region_fit.max_flatness());
  max_elongation_ = static_cast<float>(region_fit.max_bin_elongation());
  far_max_elevation_ = static_cast<float>(region_fit.max_elevation_m());
  num_rings_of_interest_ = static_cast<int>(region_fit.num_rings_of_interest());
  for (double e : region_fit.near_elevation_m()) near_elevation_.push_back(static_cast<float>(e));
  reject_vertical_ = region_fit.reject_vertical();
  vertical_seed_margin_ = static_cast<float>(region_fit.vertical_seed_margin_m());
  vertical_distance_ = static_cast<float>(region_fit.vertical_distance_m());
  seed_floor_ratio_ = region_fit.seed_floor_height_ratio();
  reference_window_ = region_fit.reference_prior_window_m();
  min_range2_ = bound_[0] * bound_[0];
  max_range2_ = bound_[4] * bound_[4];
  bin_start_.resize(num_bins_ + 1);
  bins_.resize(num_bins_);
}

void GroundSegmenter::ProcessBin(int bin, uint32_t begin, uint32_t end, bool zone0,
                                 double seed_floor_z) {
  Bin& b = bins_[bin];
  const size_t n = end - begin;
  const float* x = bx_.data() + begin;
  const float* y = by_.data() + begin;
  const float* z = bz_.data() + begin;
  uint8_t* active = active_.data() + begin;
  uint8_t* seeds = seed_scratch_.data() + begin;
  uint8_t* label = bground_.data() + begin;
  geometry::PlaneMoments moments(Eigen::Vector3d(x[0], y[0], z[0]));
  const float floor_z = zone0 ? static_cast<float>(seed_floor_z)
                              : -std::numeric_limits<float>::infinity();
  // Seed height: mean z of the lowest points above the floor (all of them
  // when none is above it).
  auto seed_height = [&]() {
    float lpr = geometry::MeanOfLowest(z, n, active, num_seed_points_, floor_z);
    if (!std::isfinite(lpr)) {
      lpr = geometry::MeanOfLowest(z, n, active, num_seed_points_,
                                   -std::numeric_limits<float>::infinity());
    }
    return lpr;
  };
  // Plane of the active points with z < top (a band 100 m deep below top).
  auto fit_below = [&](float top) {
    moments.Clear();
    geometry::SelectAndAccumulate(x, y, z, n, active, Eigen::Vector3d::UnitZ(),
                                  -(static_cast<double>(top) - 50.0), 50.0, seeds, &moments);
    return geometry::FitPlane(moments);
  };

  float lpr = seed_height();
  if (!std::isfinite(lpr)) return;
  // Vertical-structure rejection (zone 0 only).
  if (zone0 && reject_vertical_) {
    for (int iter = 0; iter < num_iterations_; ++iter) {
      const geometry::PlaneFit vertical = fit_below(lpr + vertical_seed_margin_);
      if (!vertical.ok || vertical.normal.z() >= cos_max_tilt_) break;
      const float nx = vertical.normal.x(), ny = vertical.normal.y(), nz = vertical.normal.z();
      const float d = static_cast<float>(vertical.offset);
      uint32_t removed = 0;
      for (size_t i = 0; i < n; ++i) {
        const bool on = active[i] && std::fabs(nx * x[i] + ny * y[i] + nz * z[i] + d) <
                                         vertical_distance_;
        removed += on ? 1 : 0;
        if (on) active[i] = 0;
      }
      if (removed == 0) break;
      lpr = seed_height();
      if (!std::isfinite(lpr)) return;
    }
  }

  // Ground plane from the lowest points, then refits on two-sided inliers;
  // the label of a point is its selection against the last plane but one,
  // i.e. exactly the points of the final fit.
  geometry::PlaneFit fit = fit_below(lpr + seed_margin_);
  for (int iter = 0; iter < num_iterations_ && fit.ok; ++iter) {
    moments.Clear();
    const bool changed = geometry::SelectAndAccumulate(x, y, z, n, active, fit.normal, fit.offset,
                                                       plane_distance_, label, &moments);
    if (iter > 0 && !changed) break;
    fit = geometry::FitPlane(moments);
  }
  if (!fit.ok) {
    std::fill(label, label + n, uint8_t{0});
    return;
  }
  b.ok = true;
  b.normal = fit.normal.cast<float>();
  b.centroid = fit.centroid.cast<float>();
  b.offset = static_cast<float>(fit.offset);
  b.flatness = static_cast<float>(fit.eigenvalues(0));
  b.elongation = static_cast<float>(fit.eigenvalues(2) / fit.eigenvalues(1));
}

SegmentationSummary GroundSegmenter::Segment(const float* x, const float* y, const float* z,
                                             size_t n, double height_prior_m) {
  SegmentationSummary summary;
  summary.num_points = static_cast<uint32_t>(n);
  const size_t binned = AssignBins(x, y, z, n);
  SortIntoBins(x, y, z, n, binned);
  summary.num_binned = static_cast<uint32_t>(binned);
  const bool have_prior = height_prior_m > 0.0;
  const double seed_floor_z = (have_prior && seed_floor_ratio_ > 0.0)
                                  ? -seed_floor_ratio_ * height_prior_m
                                  : -std::numeric_limits<double>::infinity();
  FitBins(seed_floor_z, &summary);
  FindReferenceHeight(height_prior_m, &summary);
  ClassifyBins(&summary);
  return summary;
}

size_t GroundSegmenter::AssignBins(const float* x, const float* y, const float* z, size_t n) {
  bin_of_.resize(n);
  r_of_.resize(n);
  std::fill(bin_start_.begin(), bin_start_.end(), 0u);
  // count[b] = bin_start_[b + 1], turned into start offsets by SortIntoBins.
  uint32_t* count = bin_start_.data() + 1;
  size_t binned = 0;
  const float min_r2 = static_cast<float>(min_range2_), max_r2 = static_cast<float>(max_range2_);
  const float b1 = static_cast<float>(bound_[1]), b2 = static_cast<float>(bound_[2]),
              b3 = static_cast<float>(bound_[3]);
  float bound_f[4], inv_width_f[4];
  for (int k = 0; k < 4; ++k) {
    bound_f[k] = static_cast<float>(bound_[k]);
    inv_width_f[k] = static_cast<float>(inv_ring_width_[k]);
  }
  for (size_t i = 0; i < n; ++i) {
    const float xi = x[i], yi = y[i], zi = z[i];
    bin_of_[i] = -1;
    // NaN fails every comparison below (and z is checked explicitly).
    const float r2 = xi * xi + yi * yi;
    if (!(r2 > min_r2 && r2 <= max_r2) || !std::isfinite(zi)) continue;
    const float r = std::sqrt(r2);
    r_of_[i] = r;
    const int zone = r < b1 ? 0 : r < b2 ? 1 : r < b3 ? 2 : 3;
    const int ring_local =
        std::min(static_cast<int>((r - bound_f[zone]) * inv_width_f[zone]), rings_[zone] - 1);
    const int sector = std::min(static_cast<int>(Azimuth02Pi(yi, xi) * sector_scale_[zone]),
                                sectors_[zone] - 1);
    const int bin = ring_first_bin_[first_ring_[zone] + ring_local] + sector;
    bin_of_[i] = bin;
    ++count[bin];
    ++binned;
  }
  return binned;
}

void GroundSegmenter::SortIntoBins(const float* x, const float* y, const float* z, size_t n,
                                   size_t binned) {
  for (int b = 0; b < num_bins_; ++b) bin_start_[b + 1] += bin_start_[b];
  num_binned_ = binned;
  bx_.resize(binned);
  by_.resize(binned);
  bz_.resize(binned);
  bsrc_.resize(binned);
  br_.resize(binned);
  bground_.assign(binned, 0);
  active_.assign(binned, 1);
  seed_scratch_.assign(binned, 0);
  // bin_start_[b] is the write cursor of bin b; restored afterwards.
  for (size_t i = 0; i < n; ++i) {
    const int b = bin_of_[i];
    if (b < 0) continue;
    const uint32_t pos = bin_start_[b]++;
    bx_[pos] = x[i];
    by_[pos] = y[i];
    bz_[pos] = z[i];
    br_[pos] = r_of_[i];
    bsrc_[pos] = static_cast<uint32_t>(i);
  }
  for (int b = num_bins_; b > 0; --b) bin_start_[b] = bin_start_[b - 1];
  bin_start_[0] = 0;
}

void GroundSegmenter::FitBins(double seed_floor_z, SegmentationSummary* summary) {
  for (int ring = 0; ring < num_rings_; ++ring) {
    const bool zone0 = ring < rings_[0];
    for (int b = ring_first_bin_[ring]; b < ring_first_bin_[ring + 1]; ++b) {
      bins_[b] = Bin();
      bins_[b].ring = ring;
      const uint32_t begin = bin_start_[b], end = bin_start_[b + 1];
      if (end - begin < min_points_per_bin_) continue;
      ProcessBin(b, begin, end, zone0, seed_floor_z);
      if (bins_[b].ok) ++summary->num_bins_fitted;
    }
  }
}

// Median centroid z of upright, sensor-facing, non-elongated bins in the
// rings of interest (ring 0 when none).
void GroundSegmenter::FindReferenceHeight(double height_prior_m, SegmentationSummary* summary) {
  const bool have_prior = height_prior_m > 0.0;
  reference_samples_.clear();
  const int reference_rings = std::min(std::max(1, num_rings_of_interest_), num_rings_);
  for (int pass = 0; pass < 2 && reference_samples_.empty(); ++pass) {
    // Pass 0 keeps bins near the height prior; pass 1 (no prior, or a prior
    // that matches nothing) takes all of them, so a wrong prior shows up as a
    // height-prior rejection rather than as missing ground.
    const bool windowed = pass == 0 && have_prior;
    if (pass == 1 && !have_prior) break;
    for (int b = 0; b < ring_first_bin_[reference_rings]; ++b) {
      const Bin& bin = bins_[b];
      if (!bin.ok || bin.normal.z() < cos_max_tilt_ || bin.offset <= 0.0f) continue;
      if (bin.elongation > max_elongation_) continue;
      if (windowed && std::fabs(bin.centroid.z() + height_prior_m) > reference_window_) continue;
      reference_samples_.push_back(bin.centroid.z());
    }
  }
  if (!reference_samples_.empty()) {
    const size_t mid = reference_samples_.size() / 2;
    std::nth_element(reference_samples_.begin(), reference_samples_.begin() + mid,
                     reference_samples_.end());
    summary->has_reference = true;
    summary->reference_z_m = reference_samples_[mid];
  }
}

// Ground likelihood per bin; clears the labels of rejected bins.
void GroundSegmenter::ClassifyBins(SegmentationSummary* summary) {
  const float ref = static_cast<float>(summary->reference_z_m);
  for (int b = 0; b < num_bins_; ++b) {
    Bin& bin = bins_[b];
    // Upright, sensor above the plane (rejects ceilings), and in the rings of
    // interest not a single-beam line.
    bool ground = bin.ok && bin.normal.z() >= cos_max_tilt_ && bin.offset > 0.0f;
    if (ground && bin.ring < num_rings_of_interest_ && bin.elongation > max_elongation_) {
      ground = false;
    }
    if (ground && summary->has_reference) {
      const float elevation = bin.centroid.z() - ref;
      if (bin.ring < num_rings_of_interest_) {
        const float limit =
            near_elevation_[std::min<size_t>(bin.ring, near_elevation_.size() - 1)];
        if (elevation > limit && bin.flatness >= max_flatness_) ground = false;
      } else if (elevation > far_max_elevation_) {
        ground = false;
      }
    }
    bin.ground = ground;
    const uint32_t begin = bin_start_[b], end = bin_start_[b + 1];
    if (!ground) {
      for (uint32_t i = begin; i < end; ++i) bground_[i] = 0;
    } else {
      ++summary->num_bins_ground;
      for (uint32_t i = begin; i < end; ++i) summary->num_ground += bground_[i];
    }
  }
}

void GroundSegmenter::GroundBinPlanes(double radius_m, std::vector<Eigen::Vector4d>* planes) const {
  planes->clear();
  const float r2 = static_cast<float>(radius_m * radius_m);
  for (const Bin& bin : bins_) {
    if (!bin.ground) continue;
    if (bin.centroid.x() * bin.centroid.x() + bin.centroid.y() * bin.centroid.y() > r2) continue;
    planes->emplace_back(bin.normal.x(), bin.normal.y(), bin.normal.z(), bin.offset);
  }
}

}  // namespace tiltcal::ground
