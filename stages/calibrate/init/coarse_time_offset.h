#ifndef TILTCAL_STAGES_CALIBRATE_INIT_COARSE_TIME_OFFSET_H_
#define TILTCAL_STAGES_CALIBRATE_INIT_COARSE_TIME_OFFSET_H_

// The clock offset tau over a wide window, before any fine solve, and the
// gyro's unit against the LiDAR's (docs/design.md §9): the angular speed of
// the gyro, |omega_m - b_g| at each IMU sample (IMU clock), against the
// LiDAR odometry's, |Log(C_{l0 li}^T C_{l0 lj})| / (t_j - t_i) for
// consecutive odometry poses i, j, at (t_i + t_j) / 2 (LiDAR clock). Speeds
// do not depend on the extrinsic rotation, so a wrong rig C_bl does not bias
// tau. Alignment: common/imu/angular_speed_alignment.h (a LiDAR stamp t_l
// happened at IMU time t_l + tau).

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/imu/angular_speed_alignment.h"
#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

struct CoarseTimeOffset {
  imu::AngularSpeedAlignment alignment;
  // The peak stands out (InitParams coarse_time_offset_min_correlation,
  // coarse_time_offset_min_peak_margin) and is not at the window's edge.
  bool trusted = false;
  std::string distrust_reason;  // empty when trusted
};

// |omega_m - b_g|, rad/s in the file's gyro unit, at the IMU times.
std::vector<imu::TimedValue> GyroAngularSpeeds(const std::vector<imu::ImuReading>& imu_samples,
                                               const Eigen::Vector3d& gyro_bias);

// Angular speed of consecutive poses (times increasing, l0_from_lidar[k] =
// C_{l0 lk}), rad/s, at the middle of each interval.
std::vector<imu::TimedValue> LidarAngularSpeeds(
    const std::vector<double>& times_s, const std::vector<Eigen::Quaterniond>& l0_from_lidar);

// Aligns the two speeds over [-coarse_time_offset_window_s, +...] and judges
// the peak. Errors: those of AlignAngularSpeeds (no overlap, no rotation).
Status EstimateCoarseTimeOffset(const std::vector<imu::TimedValue>& gyro_speed,
                                const std::vector<imu::TimedValue>& lidar_speed,
                                const proto::InitParams& params, CoarseTimeOffset* result);

// The gyro / LiDAR rate scale of a trusted peak against
// [min_gyro_to_lidar_rate_scale, max_gyro_to_lidar_rate_scale]: about
// 180/pi is a gyro in deg/s labelled rad/s (the error tells the user to set
// the rig's imu_gyro_unit: DEGPS); any other value outside is an error with
// the number (a wrong sensor or topic).
Status CheckGyroToLidarRateScale(double scale, const proto::InitParams& params);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_INIT_COARSE_TIME_OFFSET_H_
