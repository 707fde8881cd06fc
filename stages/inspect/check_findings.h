#ifndef TILTCAL_STAGES_INSPECT_CHECK_FINDINGS_H_
#define TILTCAL_STAGES_INSPECT_CHECK_FINDINGS_H_

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_units.h"
#include "common/imu/static_detection.h"
#include "common/imu/vibration.h"
#include "common/timing/clock_rate.h"
#include "stages/inspect/bag_survey.h"
#include "stages/inspect/excitation.h"
#include "stages/inspect/stamp_statistics.h"
#include "tiltcal/proto/check_params.pb.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal::inspect {

struct ImuFindings {
  StampStatistics stamps;
  imu::AccelUnitEvidence accel;  // in the published unit
  // Gyro unit from the rates alone (imu::DetectGyroUnitFromRates with
  // ImuCheckParams.gyro_rate_percentile and max_vehicle_turn_rate_radps).
  imu::GyroRateEvidence gyro;
  imu::GyroUnit gyro_unit = imu::GyroUnit::kRadiansPerSecond;
  imu::StaticInterval static_start;  // SI; times from the first IMU stamp
  Eigen::Vector3d specific_force_at_rest_mps2 = Eigen::Vector3d::Zero();
  ImuExcitation excitation;
  imu::ImuVibration vibration;  // SI units
  // A high-passed RMS above ImuCheckParams.vibration_factor times the
  // calibration's white-noise σ on some axis of the triad.
  bool gyro_vibrates = false, accel_vibrates = false;
  // The static start was found only in the low-passed readings.
  bool static_start_after_low_pass = false;
  double stamp_minus_record_s = 0.0;  // median header stamp − record time
};

struct LidarFindings {
  StampStatistics stamps;
  int64_t median_points = 0, min_points = 0, max_points = 0;  // per scan (width · height)
  CloudLayout layout;
  bool has_time_offsets = false;
  double min_time_offset_s = 0.0, max_time_offset_s = 0.0;  // over the sampled scans
  int sampled_scans = 0;
  int scans_with_ground = 0;
  double structure_fraction = 0.0;  // mean over the sampled scans
  double structure_max_range_m = 0.0;
  bool up_from_rig = false;  // up = C_bl^T f_rest/|f_rest|, else the LiDAR z
  double stamp_minus_record_s = 0.0;
};

struct ClockFindings {
  bool both = false;       // both streams have stamps
  double overlap_s = 0.0;  // negative: the spans are apart by −overlap_s
  // median(LiDAR stamp − record) − median(IMU stamp − record): with both
  // streams received promptly, τ ≈ −this (a LiDAR stamp t_l happened at IMU
  // time t_l + τ).
  double stamp_offset_difference_s = 0.0;
  // Each stream's stamp clock against the record times, and the LiDAR's
  // against the IMU's: rate_ppm > 0 the LiDAR clock runs fast, τ changes by
  // −rate · 1e-6 per second (a LiDAR stamp reads later and later).
  timing::ClockRate imu_rate, lidar_rate;
  timing::RelativeClockRate lidar_vs_imu;
};

// Everything the check says. `problems` make the bag uncalibratable (exit
// 1); `notes` say what the data mean for the calibration.
struct CheckFindings {
  std::string bag;
  std::string format;  // "ROS 1 bag", "MCAP", ...
  uint64_t file_size = 0;
  bool indexed = true;
  std::string imu_topic, lidar_topic;
  bool have_rig = false;
  double rig_imu_height_m = 0.0;
  ImuFindings imu;
  LidarFindings lidar;
  ClockFindings clock;
  bag::StaticTransforms tf_static;  // what /tf_static says about the extrinsic
  std::vector<std::string> problems;
  std::vector<std::string> notes;
};

// The analysis of a survey (no I/O). `rig` may be null (no --rig).
CheckFindings AnalyseSurvey(const BagSurvey& survey, const proto::Rig* rig,
                            const proto::CheckParams& params);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_CHECK_FINDINGS_H_
