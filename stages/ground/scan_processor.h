#ifndef TILTCAL_STAGES_GROUND_SCAN_PROCESSOR_H_
#define TILTCAL_STAGES_GROUND_SCAN_PROCESSOR_H_

#include <vector>

#include <Eigen/Core>
#include <google/protobuf/repeated_field.h>

#include "stages/ground/deskew.h"
#include "stages/ground/ground_segmentation.h"
#include "stages/ground/scan_plane.h"
#include "tiltcal/proto/ground.pb.h"
#include "tiltcal/proto/ground_params.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::ground {

// What the per-scan pipeline needs to know about the sequence.
struct GroundFrame {
  // C_sl: rotates LiDAR coordinates into the segmentation frame s whose z axis
  // is the expected up direction (identity when up is the LiDAR z axis).
  Eigen::Matrix3d s_from_lidar = Eigen::Matrix3d::Identity();
  // Expected LiDAR height above ground (m), 0 = none.
  double height_prior_m = 0.0;
};

// The frame and height prior from the rig and the params: up is
// C_bl^T (−g_f/|g_f|) when use_rig_up_direction and the rig has g_f, else the
// LiDAR z axis; the height prior is sensor_height_guess_m when > 0, else
// d_b + up_l · (C_bl^T r_b^{lb}) when the rig has d_b > 0 and r_b^{lb} is
// known (not a sequence rig whose starting_extrinsic.translation_known is
// false), else none.
GroundFrame MakeGroundFrame(const proto::Rig& rig, const proto::GroundFrameParams& params);

// Deskew + segmentation + plane fit of one scan at a time; buffers are reused.
// Hands each component its own part of the params.
class ScanProcessor {
 public:
  // `deskewer` may be null (no deskewing); it is used when
  // params.deskew.enabled. The params must have passed ValidateGroundParams
  // (stages/ground/ground_params.h).
  ScanProcessor(const proto::GroundParams& params, const GroundFrame& frame, Deskewer* deskewer);

  // Processes one scan. When deskewing applies, the scan's points are moved
  // in place and scan->deskewed() is set. The returned plane has no NaN.
  proto::GroundPlane Process(proto::Scan* scan);

  // Seconds spent in the last Process() call, per step.
  double last_deskew_s() const { return deskew_s_; }
  double last_segment_s() const { return segment_s_; }
  double last_fit_s() const { return fit_s_; }

 private:
  // Steps of Process(): deskews the scan in place (false: rejected for lack
  // of IMU coverage, `out` filled); the points in frame s (columns, valid
  // until the next call); the fitted plane back in the LiDAR frame.
  bool Deskew(proto::Scan* scan, proto::GroundPlane* out);
  void ToSegmentationFrame(const proto::Scan& scan, const float** x, const float** y,
                           const float** z);
  void SetPlaneInLidar(const ScanPlane& plane, proto::GroundPlane* out) const;

  GroundFrame frame_;
  bool level_ = false;
  Deskewer* deskewer_;  // null when deskewing is off
  bool require_imu_coverage_;
  bool store_point_masks_;
  GroundSegmenter segmenter_;
  ScanPlaneFitter fitter_;
  std::vector<float> sx_, sy_, sz_;
  std::vector<uint8_t> inlier_;
  double deskew_s_ = 0, segment_s_ = 0, fit_s_ = 0;
};

// Packs a per-binned-point flag into a per-source-point bit mask: bit
// (i % 64) of word i / 64 is point i.
void PackMask(const uint8_t* binned_flag, const uint32_t* binned_source, size_t num_binned,
              size_t num_points, google::protobuf::RepeatedField<uint64_t>* mask);

// Bit of point i in a mask packed by PackMask (false beyond its end).
inline bool MaskBit(const google::protobuf::RepeatedField<uint64_t>& mask, size_t i) {
  const size_t word = i >> 6;
  return word < static_cast<size_t>(mask.size()) && ((mask.Get(word) >> (i & 63u)) & 1u);
}

}  // namespace tiltcal::ground

#endif  // TILTCAL_STAGES_GROUND_SCAN_PROCESSOR_H_
