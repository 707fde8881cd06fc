#ifndef TILTCAL_COMMON_IMU_STATIC_DETECTION_H_
#define TILTCAL_COMMON_IMU_STATIC_DETECTION_H_

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"
#include "common/imu/vibration.h"

namespace tiltcal::imu {

// No defaults: every field is set from the params file (each stage's static_detection params).
struct StaticDetectionOptions {
  double window_s;  // length of one test window, s
  double hop_s;  // window step, s (resolution of the interval ends)
  double max_gyro_std_radps;  // per-axis standard deviation bound, rad/s
  double max_accel_std_mps2;  // per-axis standard deviation bound, m/s²
  double max_gyro_mean_radps;  // |mean gyro| bound (rules out steady turning), rad/s
  double min_duration_s;  // shorter static runs are not reported
  // The window tests run on the zero-phase low-pass of the readings at this
  // cut-off (common/imu/vibration.h), so that an engine or wheels the IMU
  // feels while the vehicle stands (vibration far above the cut-off) do not
  // hide a still interval; 0: on the readings as recorded.
  LowPassOptions low_pass;
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
// time order.
// With low_pass.cutoff_hz > 0 the windows are tested on the low-passed
// readings, which lack the first and last low_pass.span_s / 2 (the filter's
// half span); a run that begins within one hop of the low-passed readings'
// first sample begins at the first reading, and likewise at the end. The
// interval's indices, means and standard deviations are those of the
// readings as recorded (a zero-mean vibration averages out of the means). Window k covers [t0 + k hop, t0 + k hop + window); it is static
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
