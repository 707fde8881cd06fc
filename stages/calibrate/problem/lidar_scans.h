#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_LIDAR_SCANS_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_LIDAR_SCANS_H_

// The raw (not deskewed) LiDAR scans as the calibrator keeps them in memory,
// and their mapping to the world frame a through the current state.
//
// Times: seconds relative to the first IMU stamp, on the LiDAR clock:
//   t_j = (stamp_ns - first_imu_stamp_ns) * 1e-9 + point_time_s[j],
// and the point happened at IMU time t_j + tau (with a clock drift, tau at
// the scan stamp: CalibrationState::TimeOffsetAt(t_k) for the whole sweep).

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/status.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

struct LidarScan {
  int index = 0;          // record index in the scan stream
  double stamp_s = 0.0;   // scan stamp t_k, LiDAR clock, s from the first IMU stamp
  std::vector<Eigen::Vector3f> points;  // frame l, m
  std::vector<float> point_time_s;      // t_j - t_k, s
  double min_time_s = 0.0;              // min / max of point_time_s
  double max_time_s = 0.0;
};

// Reads a Scan stream (scans.binpb[.lz4]). Non-finite points and points out
// of [params.min_range_m, params.max_range_m] are dropped; of the rest, points
// 0, k, 2k, ... of each scan are kept (k = params.point_stride). Mismatched
// column lengths are an error naming the file and record; scans left empty
// are kept (with no points).
Status ReadLidarScans(const std::string& path, int64_t first_imu_stamp_ns,
                      const proto::LidarScanParams& params, std::vector<LidarScan>* scans);

// T_al(t) = (C_ab(t) C_bl, C_ab(t) r_b^{lb} + r_a^{ba}(t)) of one scan's
// sweep, tabulated on nodes spaced <= node_spacing_s over
// [t_k + min_time, t_k + max_time] (LiDAR clock, evaluated at + tau) and
// interpolated per point (linear translation, normalised-linear quaternion).
class ScanPoseTable {
 public:
  // Returns false when the sweep (+ tau) is not inside the spline.
  bool Build(const CalibrationState& state, const LidarScan& scan, double node_spacing_s);
  // a_from_lidar at point time offset dt_s (relative to the scan stamp).
  void Interpolate(double dt_s, Eigen::Quaterniond* rotation, Eigen::Vector3d* translation) const;
  // p_a for point j of the scan.
  Eigen::Vector3d ToWorld(const LidarScan& scan, size_t j) const;

 private:
  double begin_s_ = 0.0;
  double spacing_s_ = 1.0;
  std::vector<Eigen::Quaterniond> rotations_;
  std::vector<Eigen::Vector3d> translations_;
};

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_LIDAR_SCANS_H_
