#ifndef TILTCAL_STAGES_EXPORT_EXPORTED_CALIBRATION_H_
#define TILTCAL_STAGES_EXPORT_EXPORTED_CALIBRATION_H_

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/io/eigen_proto.h"
#include "common/status.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::exporter {

// One-sigma uncertainties of a calibration (the square roots of the
// covariance's diagonal, docs/design.md §11).
struct ExportedSigma {
  // About the LiDAR axes: C_bl is perturbed on the right, C_bl Exp(δ), deg.
  Eigen::Vector3d rotation_deg = Eigen::Vector3d::Zero();
  Eigen::Vector3d translation_m = Eigen::Vector3d::Zero();  // IMU axes
  double time_offset_s = 0;
};

// What every export format writes: the extrinsic in both directions, τ, σ,
// the verdict, and the names of the two frames.
struct ExportedCalibration {
  std::string source;        // the calibration file, as given
  Rigid3d imu_from_lidar;    // (C_bl, r_b^{lb}): x_imu = C_bl x_lidar + r_b^{lb}
  Rigid3d lidar_from_imu;    // the inverse: (C_lb, r_l^{bl} = -C_lb r_b^{lb})
  double time_offset_s = 0;  // τ: t_imu = t_lidar + τ
  std::optional<ExportedSigma> sigma;  // absent when the file has none
  std::string verdict;                 // "OK", "WEAK", "SUSPECT", "UNSET"
  std::vector<std::string> verdict_reasons;
  // What to do about a drifting LiDAR clock (CalibrationResult.time_offset_drift
  // estimated: its rate and tau at both ends; else decode's clock_drift
  // finding), one sentence; "" when the clocks did not drift.
  std::string clock_drift_advice;
  std::string imu_frame;    // e.g. "imu_link"
  std::string lidar_frame;  // e.g. "lidar_link"
};

// Checks that `calibration` holds a usable extrinsic (a finite quaternion of
// non-zero norm, finite numbers) and gathers what the formats write. The error
// names `source` and the field at fault.
Status MakeExportedCalibration(const proto::CalibrationResult& calibration,
                               const std::string& source, const std::string& imu_frame,
                               const std::string& lidar_frame, ExportedCalibration* exported);

// A frame name that is safe in XML attributes, YAML and a shell command line:
// letters, digits, '_', '/', '-', '.'; not empty.
Status CheckFrameName(const std::string& flag, const std::string& name);

}  // namespace tiltcal::exporter

#endif  // TILTCAL_STAGES_EXPORT_EXPORTED_CALIBRATION_H_
