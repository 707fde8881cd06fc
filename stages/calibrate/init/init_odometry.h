#ifndef TILTCAL_STAGES_CALIBRATE_INIT_INIT_ODOMETRY_H_
#define TILTCAL_STAGES_CALIBRATE_INIT_INIT_ODOMETRY_H_

// The initialisation's LiDAR odometry (steps 3 and 3b of initialisation.h):
// the scans registered with lidar_odometry.h, deskewed and given a rotation
// prior by the state's rotation spline and C_bl, and the wide-window time
// offset from the angular speeds of gyro and odometry.

#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "stages/calibrate/init/initialisation.h"
#include "stages/calibrate/odometry/lidar_odometry.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

// Step 3: the odometry's poses and, per pose, its scan and C_ab at the scan
// stamp + tau (the state's).
struct OdometryRun {
  std::vector<LidarOdometryPose> poses;
  std::vector<int> scan_of_pose;
  std::vector<Eigen::Quaterniond> imu_rotations;
  // Of the poses used further on (pose 0 and every registered one): their
  // indices, C_ab and C_{l0 lk}.
  std::vector<size_t> used;
  std::vector<Eigen::Quaterniond> imu_used;
  std::vector<Eigen::Quaterniond> lidar_used;
};

// Odometry on scans deskewed with the rotation spline at the state's tau
// (positions are still zero, so only rotation and the lever arm move the
// points) and a rotation prior from it; scans whose stamp + tau is outside
// the spline are left out. Without gyro_aided: raw scans, no prior (the
// gyro's speeds are then only compared with the LiDAR's, not trusted).
// Fills the odometry counts of *report.
OdometryRun RunOdometry(const std::vector<LidarScan>& scans, const CalibrationState& state,
                        const proto::CalibrateParams& params, bool gyro_aided,
                        InitialisationReport* report);

// Step 3b: tau over the wide window from the angular speeds of the gyro and
// of the odometry (run at the state's tau), and the centre of the later tau
// searches in report->time_offset_center_s: the coarse tau when trusted
// (rounded to the grid search's step, so that the grid keeps its points),
// else 0. report->coarse says how it went.
Status EstimateCoarseTau(const OdometryRun& run, const std::vector<LidarScan>& scans,
                         const std::vector<imu::ImuReading>& imu_samples,
                         const proto::CalibrateParams& params, const CalibrationState& state,
                         InitialisationReport* report);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_INIT_INIT_ODOMETRY_H_
