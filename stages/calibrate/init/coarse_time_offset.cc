#include "stages/calibrate/init/coarse_time_offset.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/imu/imu_units.h"

namespace tiltcal::calibrate {

std::vector<imu::TimedValue> GyroAngularSpeeds(const std::vector<imu::ImuReading>& imu_samples,
                                               const Eigen::Vector3d& gyro_bias) {
  std::vector<imu::TimedValue> speeds;
  speeds.reserve(imu_samples.size());
  for (const imu::ImuReading& r : imu_samples) {
    speeds.push_back({r.time_s, (r.angular_velocity_radps - gyro_bias).norm()});
  }
  return speeds;
}

std::vector<imu::TimedValue> LidarAngularSpeeds(
    const std::vector<double>& times_s, const std::vector<Eigen::Quaterniond>& l0_from_lidar) {
  std::vector<imu::TimedValue> speeds;
  for (size_t k = 0; k + 1 < times_s.size() && k + 1 < l0_from_lidar.size(); ++k) {
    const double dt = times_s[k + 1] - times_s[k];
    if (!(dt > 0.0)) continue;
    const double angle =
        Eigen::AngleAxisd(l0_from_lidar[k].conjugate() * l0_from_lidar[k + 1]).angle();
    speeds.push_back({0.5 * (times_s[k] + times_s[k + 1]), angle / dt});
  }
  return speeds;
}

Status EstimateCoarseTimeOffset(const std::vector<imu::TimedValue>& gyro_speed,
                                const std::vector<imu::TimedValue>& lidar_speed,
                                const proto::InitParams& params, CoarseTimeOffset* result) {
  *result = CoarseTimeOffset();
  if (lidar_speed.size() < 3) {
    return Status::Error(fmt::format(
        "coarse time offset: {} LiDAR angular speeds (too few registered scans)",
        lidar_speed.size()));
  }
  imu::AngularSpeedAlignmentOptions options;
  options.max_time_offset_s = params.coarse_time_offset_window_s();
  options.grid_step_s = params.coarse_time_offset_grid_step_s();
  options.min_overlap_s = params.coarse_time_offset_min_overlap_fraction() *
                          (lidar_speed.back().time_s - lidar_speed.front().time_s);
  // The ratio of two slow rotations is noise: scale from LiDAR speeds above
  // coarse_time_offset_min_reference_speed_radps (absent: 0.05 rad/s).
  options.min_reference_speed = params.has_coarse_time_offset_min_reference_speed_radps()
                                    ? params.coarse_time_offset_min_reference_speed_radps()
                                    : 0.05;
  TILTCAL_RETURN_IF_ERROR(
      imu::AlignAngularSpeeds(gyro_speed, lidar_speed, options, &result->alignment));
  const imu::AngularSpeedAlignment& a = result->alignment;
  if (a.at_search_bound) {
    result->distrust_reason = fmt::format(
        "the correlation peaks at the edge of the +-{} s window "
        "(init.coarse_time_offset_window_s)",
        params.coarse_time_offset_window_s());
  } else if (a.correlation < params.coarse_time_offset_min_correlation()) {
    result->distrust_reason = fmt::format(
        "correlation {:.3f} below init.coarse_time_offset_min_correlation {:.3f}", a.correlation,
        params.coarse_time_offset_min_correlation());
  } else if (a.correlation - a.second_peak_correlation <
             params.coarse_time_offset_min_peak_margin()) {
    result->distrust_reason = fmt::format(
        "the peak (r = {:.3f}) does not stand out from the second peak (r = {:.3f}; "
        "init.coarse_time_offset_min_peak_margin {:.3f}): repetitive motion",
        a.correlation, a.second_peak_correlation, params.coarse_time_offset_min_peak_margin());
  }
  result->trusted = result->distrust_reason.empty();
  return Status::Ok();
}

Status CheckGyroToLidarRateScale(double scale, const proto::InitParams& params) {
  if (scale >= params.min_gyro_to_lidar_rate_scale() &&
      scale <= params.max_gyro_to_lidar_rate_scale()) {
    return Status::Ok();
  }
  const double degrees_per_radian = 1.0 / imu::kRadiansPerDegree;
  if (scale >= params.min_gyro_to_lidar_rate_scale() * degrees_per_radian &&
      scale <= params.max_gyro_to_lidar_rate_scale() * degrees_per_radian) {
    return Status::Error(fmt::format(
        "the gyro turns {:.1f} times faster than the LiDAR (180/pi = 57.3): the IMU file's "
        "angular velocities are in deg/s, not rad/s; set imu_gyro_unit: DEGPS in the rig",
        scale));
  }
  return Status::Error(fmt::format(
      "the gyro's angular speed is {:.3f} times the LiDAR odometry's (expected within "
      "[{}, {}]: init.min_gyro_to_lidar_rate_scale, init.max_gyro_to_lidar_rate_scale): "
      "the IMU and the LiDAR do not see the same motion (wrong sensor, topic or unit)",
      scale, params.min_gyro_to_lidar_rate_scale(), params.max_gyro_to_lidar_rate_scale()));
}

}  // namespace tiltcal::calibrate
