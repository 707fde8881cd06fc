#ifndef TILTCAL_COMMON_IMU_STATIC_DETECTION_H_
#define TILTCAL_COMMON_IMU_STATIC_DETECTION_H_

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"

namespace tiltcal::imu {

// No defaults: every field is set from the params file (each stage's static_detection params).
struct StaticDetectionOptions {
  double window_s;  // length of one test window, s
  double hop_s;  // window step, s (resolution of the interval ends)
  double max_gyro_std_radps;  // per-axis standard deviation bound, rad/s
  double max_accel_std_mps2;  // per-axis standard deviation bound, m/s²
  double max_gyro_mean_radps;  // |mean gyro| bound (rules out steady turning), rad/s
  double min_duration_s;  // shorter static runs are not reported
};

// A time interval in which the IMU stood still: [begin_s, end_s] and the
// samples [begin_index, end_index), with their mean readings.
struct StaticInterval {
  bool found = false;
  double begin_s = 0.0;
  double end_s = 0.0;
  size_t begin_index = 0;
  size_t end_index = 0;
  Eigen::Vector3d mean_gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_accel_mps2 = Eigen::Vector3d::Zero();
  double accel_std_mps2 = 0.0;  // largest per-axis standard deviation
  double gyro_std_radps = 0.0;
};

// Every maximal run of static windows lasting at least min_duration_s, in
// time order. Window k covers [t0 + k hop, t0 + k hop + window); it is static
// when every axis of gyro and accelerometer has a standard deviation below the
// bounds and the mean gyro norm is below max_gyro_mean_radps. Samples must be
// valid (ValidateImuReadings).
std::vector<StaticInterval> DetectStaticIntervals(const std::vector<ImuReading>& samples,
                                                  const StaticDetectionOptions& options);

// The static interval that starts at the first sample (found = false when the
// sequence does not start still for at least min_duration_s).
StaticInterval DetectStaticStart(const std::vector<ImuReading>& samples,
                                 const StaticDetectionOptions& options);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_STATIC_DETECTION_H_
