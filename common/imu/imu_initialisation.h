#ifndef TILTCAL_COMMON_IMU_IMU_INITIALISATION_H_
#define TILTCAL_COMMON_IMU_IMU_INITIALISATION_H_

#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"
#include "common/imu/static_detection.h"
#include "common/status.h"

namespace tiltcal::imu {

// IMU-only initial values: gyro bias and gravity direction in the world
// frame a (the IMU frame at the FIRST sample, so C_ab(t_0) = 1).
// At rest r̈_a = 0, so f_m = −C_ab^T g_a + b_a and g_a = −C_ab f_m (b_a = 0).
//
// Accelerometer bias: from one static attitude only the component of b_a
// along gravity would show (as |mean f| ≠ |g|); its other components cannot
// be told from a gravity direction change. It is therefore zero here, and the
// norm mismatch is reported for diagnosis only.
// No defaults: every field is set from the params file (calibrate and gravity params).
struct ImuInitialisationOptions {
  StaticDetectionOptions static_detection;
  double gravity_norm_mps2;  // |g_a|
  // Without a static start, g_a comes from the first this-many seconds.
  double fallback_window_s;
};

struct ImuInitialisation {
  StaticInterval static_start;
  bool from_static_start = false;  // the values below come from a static start
  // Mean gyro over the static start; zero (unobserved) without one.
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  // g_a = −|g| normalise(mean_i C_ab(t_i) f_i) over the averaging window.
  Eigen::Vector3d gravity_in_world_mps2 = Eigen::Vector3d::Zero();
  // |mean_i C_ab(t_i) f_i| − |g| over the window, m/s² (bias / scale hint).
  double accel_norm_mismatch_mps2 = 0.0;
  double averaging_begin_s = 0.0;
  double averaging_end_s = 0.0;
  int num_samples_averaged = 0;
};

// Gyro bias and gravity from the static start, or from the first
// fallback_window_s seconds (rotation-compensated with the integrated gyro,
// zero bias) when there is none.
Status InitialiseImu(const std::vector<ImuReading>& samples,
                     const ImuInitialisationOptions& options, ImuInitialisation* out);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_IMU_INITIALISATION_H_
