#ifndef TILTCAL_STAGES_GROUND_GROUND_SEGMENTATION_H_
#define TILTCAL_STAGES_GROUND_GROUND_SEGMENTATION_H_

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal::ground {

// Zone boundaries b0..b4 (m): b0 = min_range_m, b4 = max_range_m, b1..b3 from
// boundaries_m when it has 3 values, else the Patchwork++ rule
// b1 = (7 b0 + b4)/8, b2 = (3 b0 + b4)/4, b3 = (b0 + b4)/2.
void ZoneBoundaries(const proto::ZoneModelParams& zone_model, double bound_m[5]);

// Fast atan2 in [0, 2π), max error ~1e-5 rad (for binning only).
float Azimuth02Pi(float y, float x);

// Summary of one segmentation.
struct SegmentationSummary {
  uint32_t num_points = 0;        // input points
  uint32_t num_binned = 0;        // finite points inside the CZM range
  uint32_t num_ground = 0;        // labelled ground
  uint32_t num_bins_fitted = 0;   // bins with a plane
  uint32_t num_bins_ground = 0;   // bins accepted as ground
  bool has_reference = false;     // reference_z is known
  double reference_z_m = 0.0;     // ground height of the scan in frame s (≈ −d_l)
};

// Ground segmentation of the Patchwork++ class (our own implementation),
// in the segmentation frame s (z = expected up, sensor at the origin):
//  1. concentric zone model: points binned by horizontal range and azimuth
//     into 4 zones of equal-width rings and equal-angle sectors, with a
//     counting sort (no comparison sort) into contiguous per-bin columns;
//  2. per bin, in zone 0, vertical-structure rejection (R-VPF);
//  3. per bin, ground plane fit from the lowest points (seed height = mean of
//     the num_seed_points lowest z, seeds below it + margin) refined
//     num_iterations times on two-sided inliers;
//  4. ground likelihood per bin: uprightness (tilt), sensor above the plane
//     (rejects ceilings), elevation above the scan's ground reference
//     (median centroid height of the near bins; elevated near bins must be
//     flat), elongation of near bins (single-beam lines) and a far-ring
//     elevation guard.
// Stateless between scans: the result depends only on the scan, the params
// and the height prior. Buffers are reused between calls.
class GroundSegmenter {
 public:
  // The params must have passed ValidateZoneModelParams and
  // ValidateRegionFitParams (stages/ground/ground_params.h).
  GroundSegmenter(const proto::ZoneModelParams& zone_model,
                  const proto::RegionFitParams& region_fit);

  // Segments n points (columns x, y, z, frame s, metres). height_prior_m > 0
  // enables the prior-based parts (seed floor, reference window).
  SegmentationSummary Segment(const float* x, const float* y, const float* z, size_t n,
                              double height_prior_m);

  // Binned horizontal ranges: min_range_m < r <= max_range_m (m).
  double min_range_m() const { return bound_[0]; }
  double max_range_m() const { return bound_[4]; }

  // Results of the last Segment(), in binned order (grouped by bin):
  // coordinates, the source index of each point, and the ground label.
  size_t num_binned() const { return num_binned_; }
  const float* binned_x() const { return bx_.data(); }
  const float* binned_y() const { return by_.data(); }
  const float* binned_z() const { return bz_.data(); }
  const float* binned_range() const { return br_.data(); }  // horizontal range, m
  const uint32_t* binned_source() const { return bsrc_.data(); }
  const uint8_t* binned_ground() const { return bground_.data(); }

  // Planes (n_x, n_y, n_z, d) of the bins accepted as ground whose centroid
  // lies within `radius_m` (horizontal), in bin order: plane hypotheses for
  // the per-scan fit.
  void GroundBinPlanes(double radius_m, std::vector<Eigen::Vector4d>* planes) const;

 private:
  struct Bin {
    bool ok = false;
    bool ground = false;
    int ring = 0;
    Eigen::Vector3f normal = Eigen::Vector3f::UnitZ();  // n_z >= 0
    Eigen::Vector3f centroid = Eigen::Vector3f::Zero();
    float offset = 0.0f;       // n·p + offset = 0
    float flatness = 0.0f;     // smallest covariance eigenvalue, m^2
    float elongation = 0.0f;   // largest / middle covariance eigenvalue
  };

  // Steps of Segment(): bin index of every point and the per-bin counts
  // (returns the number of binned points); counting sort into contiguous
  // per-bin columns; per-bin plane fits; the scan's ground reference height;
  // the ground likelihood of every bin.
  size_t AssignBins(const float* x, const float* y, const float* z, size_t n);
  void SortIntoBins(const float* x, const float* y, const float* z, size_t n, size_t binned);
  void FitBins(double seed_floor_z, SegmentationSummary* summary);
  void FindReferenceHeight(double height_prior_m, SegmentationSummary* summary);
  void ClassifyBins(SegmentationSummary* summary);
  void ProcessBin(int bin, uint32_t begin, uint32_t end, bool zone0, double seed_floor_z);

  // Layout.
  double bound_[5];
  int rings_[4];
  int sectors_[4];
  double inv_ring_width_[4];
  float sector_scale_[4];
  int first_ring_[4];
  std::vector<int> ring_first_bin_;  // per global ring
  int num_rings_ = 0;
  int num_bins_ = 0;

  // Settings.
  int num_iterations_;
  uint32_t num_seed_points_;
  float seed_margin_;
  float plane_distance_;
  uint32_t min_points_per_bin_;
  float cos_max_tilt_;
  float max_flatness_;
  float max_elongation_;
  float far_max_elevation_;
  int num_rings_of_interest_;
  std::vector<float> near_elevation_;
  bool reject_vertical_;
  float vertical_seed_margin_;
  float vertical_distance_;
  double seed_floor_ratio_;
  double reference_window_;
  double min_range2_, max_range2_;

  // Buffers reused between scans.
  std::vector<int32_t> bin_of_;
  std::vector<float> r_of_;
  std::vector<uint32_t> bin_start_;
  std::vector<float> bx_, by_, bz_, br_;
  std::vector<uint32_t> bsrc_;
  std::vector<uint8_t> bground_;
  std::vector<uint8_t> active_;
  std::vector<uint8_t> seed_scratch_;
  std::vector<float> reference_samples_;
  std::vector<Bin> bins_;
  size_t num_binned_ = 0;
};

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_GROUND_SEGMENTATION_H_
