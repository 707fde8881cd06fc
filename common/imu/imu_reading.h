#ifndef TILTCAL_COMMON_IMU_IMU_READING_H_
#define TILTCAL_COMMON_IMU_IMU_READING_H_

#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace tiltcal::imu {

// One IMU sample in the IMU frame b (docs/design.md §6):
//   ω_m = ω_b(t) + b_g + n,   f_m = C_ab(t)^T (r̈_a(t) − g_a) + b_a + n.
// time_s: seconds relative to the sequence start, IMU clock.
struct ImuReading {
  double time_s = 0.0;
  Eigen::Vector3d angular_velocity_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d linear_acceleration_mps2 = Eigen::Vector3d::Zero();  // specific force f_m
};

// Error when empty, non-finite or not strictly increasing in time; the
// message names the sample index ("IMU sample 12: ...").
Status ValidateImuReadings(const std::vector<ImuReading>& samples);

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_IMU_READING_H_
