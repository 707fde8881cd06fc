#ifndef TILTCAL_STAGES_INSPECT_EXCITATION_H_
#define TILTCAL_STAGES_INSPECT_EXCITATION_H_

#include <vector>

#include <Eigen/Core>

#include "common/imu/imu_reading.h"

namespace tiltcal::inspect {

// Centred moving average over `window` samples (shrunk at the ends; a window
// of 1 or less returns the values).
std::vector<double> MovingAverage(const std::vector<double>& values, int window);

// Sign changes with hysteresis h: the state becomes + when a value exceeds
// +h and − when one falls below −h (values in between keep the state); every
// change of an established state counts.
int CountSignChanges(const std::vector<double>& values, double hysteresis);

// No defaults: every field is set from the params file (check params: excitation).
struct ExcitationOptions {
  double smoothing_window_s;
  double yaw_rate_hysteresis_radps;
  double lateral_accel_hysteresis_mps2;
};

// How the motion excites the calibration, from SI readings in the IMU frame b.
//   yaw rate      ω_yaw = (ω_m − b_g) · u, u = unit up in b (the specific
//                 force at rest, f_rest / |f_rest|)
//   lateral accel a_lat = (f_m − f_rest) · y_h, y_h = the IMU y axis made
//                 horizontal (x when y is within 60 deg of vertical)
// both smoothed over smoothing_window_s before counting sign changes.
struct ImuExcitation {
  int yaw_rate_sign_changes = 0;
  int lateral_accel_reversals = 0;
  double max_abs_yaw_rate_radps = 0.0;      // of the smoothed yaw rate
  double max_abs_lateral_accel_mps2 = 0.0;  // of the smoothed lateral acceleration
  double rotation_speed_p95_radps = 0.0;    // 95th percentile of |ω_m − b_g|
  bool lateral_axis_is_x = false;
};
ImuExcitation MeasureImuExcitation(const std::vector<imu::ImuReading>& samples,
                                   const Eigen::Vector3d& gyro_bias_radps,
                                   const Eigen::Vector3d& specific_force_at_rest_mps2,
                                   const ExcitationOptions& options);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_EXCITATION_H_
