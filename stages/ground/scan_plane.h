#ifndef TILTCAL_STAGES_GROUND_SCAN_PLANE_H_
#define TILTCAL_STAGES_GROUND_SCAN_PLANE_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/geometry/plane_fit.h"
#include "stages/ground/ground_segmentation.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal::ground {

// One plane per scan from the segmented ground points, in frame s.
struct ScanPlane {
  proto::GroundRejectReason reason = proto::GROUND_OK;
  std::string detail;               // numbers behind a rejection
  geometry::PlaneFit fit;           // oriented towards the sensor (d > 0) when ok
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();  // of (n_x, n_y, n_z, d), frame s
  double rms_m = 0.0;               // inlier point-to-plane RMS
  double coverage = 0.0;            // fraction of azimuth sectors with inliers
  double radial_spread = 0.0;       // 90th / 10th percentile of inlier ranges
  double tilt_from_up_deg = 0.0;    // angle between n and the s-frame z axis
  double fit_radius_m = 0.0;
  uint32_t num_candidates = 0;      // ground points inside the fit radius
  uint32_t num_inliers = 0;
  bool has_plane() const { return fit.ok; }
};

// Near-field robust plane fit of one scan with the sign rule (normal towards
// the sensor, d > 0), the covariance floors and the per-scan quality gates
// (ApplyScanPlaneGates); the tilt-jump gate is a sequence pass
// (ApplyTiltJumpGate). Buffers are reused between scans.
class ScanPlaneFitter {
 public:
  // `plane_fit` must have passed ValidateScanPlaneFitParams
  // (stages/ground/ground_params.h).
  ScanPlaneFitter(const proto::ScanPlaneFitParams& plane_fit,
                  const proto::ScanPlaneGateParams& gates,
                  const proto::PlaneCovarianceFloorParams& covariance_floor);

  // Fits the plane to the ground points of the segmenter's last scan.
  // `inlier` receives, per binned point (segmenter order), 1 when the point
  // is used by the final fit. height_prior_m > 0 enables the height gate.
  ScanPlane Fit(const GroundSegmenter& segmenter, const SegmentationSummary& summary,
                double height_prior_m, std::vector<uint8_t>* inlier);

 private:
  // Steps of Fit(): the fit radius (fixed, or sized to where the lowest beam
  // meets the ground); the ground points within it; the robust plane from the
  // best ground-bin hypothesis; azimuth coverage and radial spread of the
  // inliers.
  double FitRadius(const GroundSegmenter& segmenter);
  void SelectCandidates(const GroundSegmenter& segmenter, double radius_m);
  geometry::PlaneFit FitCandidates(const GroundSegmenter& segmenter, double radius_m);
  void MeasureInliers(const GroundSegmenter& segmenter, ScanPlane* plane,
                      std::vector<uint8_t>* inlier);

  proto::ScanPlaneFitParams plane_fit_;
  proto::ScanPlaneGateParams gates_;
  proto::PlaneCovarianceFloorParams covariance_floor_;
  size_t num_range_bins_ = 0;          // of histogram_, up to the segmenter's max range
  std::vector<uint32_t> candidates_;   // binned index of each candidate
  std::vector<float> cx_, cy_, cz_;     // candidate coordinates, contiguous
  std::vector<uint32_t> histogram_;     // horizontal ranges, 5 cm bins
  std::vector<Eigen::Vector4d> hypotheses_;  // ground bin planes (n, d)
  std::vector<uint8_t> fit_inlier_;
  std::vector<uint32_t> sector_count_;
};

// The covariance of (n, d) in frame s of a fitted plane: the first-order PCA
// covariance from the inliers' range noise plus the floors,
// (normal_deg in rad)^2 (I − n nᵀ) on the normal block and height_m^2 on var(d).
Eigen::Matrix4d PlaneCovarianceWithFloors(const geometry::PlaneFit& fit,
                                          const proto::PlaneCovarianceFloorParams& floor);

// The per-scan gates, in order of severity: too few inliers, plane through
// the sensor, normal too far from up, azimuth coverage, radial spread, RMS,
// height prior (only when height_prior_m > 0). Sets plane->reason and
// plane->detail for the first gate that fails.
void ApplyScanPlaneGates(const proto::ScanPlaneGateParams& gates, double height_prior_m,
                         ScanPlane* plane);

// Sequence gate: a valid plane whose normal is more than max_jump_deg from
// the normalised mean normal of the valid planes within ±window records
// (excluding itself; at least 2 needed) is rejected with GROUND_TILT_JUMP
// (max_jump_deg 0: never). Uses only the values in `planes`, so the result
// does not depend on the order in which scans were processed. Fills
// tilt_jump_deg.
void ApplyTiltJumpGate(const proto::TiltJumpGateParams& gate,
                       std::vector<proto::GroundPlane>* planes);

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_SCAN_PLANE_H_
