#ifndef TILTCAL_TESTS_COMMON_IMU_IMU_TEST_OPTIONS_H_
#define TILTCAL_TESTS_COMMON_IMU_IMU_TEST_OPTIONS_H_

#include "common/imu/imu_initialisation.h"
#include "common/imu/static_detection.h"

namespace tiltcal::imu::testing {

// The option structs have no defaults (the stages fill them from params);
// these are the values of the stages' default params, spelled for the tests.
inline StaticDetectionOptions StaticDetectionTestOptions() {
  StaticDetectionOptions options;
  options.window_s = 0.5;
  options.hop_s = 0.1;
  options.max_gyro_std_radps = 0.01;
  options.max_accel_std_mps2 = 0.05;
  options.max_gyro_mean_radps = 0.05;
  options.min_duration_s = 1.0;
  return options;
}

inline ImuInitialisationOptions ImuInitialisationTestOptions() {
  ImuInitialisationOptions options;
  options.static_detection = StaticDetectionTestOptions();
  options.gravity_norm_mps2 = 9.81;
  options.fallback_window_s = 2.0;
  return options;
}

}  // namespace tiltcal::imu::testing

#endif  // TILTCAL_TESTS_COMMON_IMU_IMU_TEST_OPTIONS_H_
