#ifndef TILTCAL_STAGES_SIMULATE_IMU_SIMULATOR_H_
#define TILTCAL_STAGES_SIMULATE_IMU_SIMULATOR_H_

#include <cstdint>
#include <string>

#include <Eigen/Core>

#include "bag/ros1/bag_writer.h"
#include "common/status.h"
#include "stages/simulate/imu_intrinsics.h"
#include "stages/simulate/imu_schedule.h"
#include "stages/simulate/imu_vibration.h"
#include "stages/simulate/random.h"
#include "stages/simulate/scenario.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::simulate {


// The IMU: samples at rate_hz from the IMU clock's start, with
//   ω_m = ω_b + b_g + n_g,   f_m = C_wb^T (r̈_w − g_w) + b_a + n_a,
// white noise σ = density · sqrt(rate), bias random walk σ = density / sqrt(rate),
// from its own random stream. Every sample is simulated at its nominal time;
// the schedule (imu_schedule.h) gives its header stamp and whether it is
// written; the values are written in the units of params.faults (SI / factor).
class ImuSimulator {
 public:
  ImuSimulator(const proto::SimulateParams& params, const Scenario& scenario);

  // Simulates the samples stamped up to `stamp_ns` (all of them for
  // INT64_MAX) not yet simulated, and writes those the schedule keeps.
  Status WriteUpTo(int64_t stamp_ns, uint32_t connection, ros1::BagWriter* writer);

  double max_yaw_rate() const { return max_yaw_rate_; }
  int num_dropped() const { return schedule_.num_dropped; }
  // The biases of the last sample.
  const Eigen::Vector3d& last_gyro_bias() const { return last_gyro_bias_; }
  const Eigen::Vector3d& last_accel_bias() const { return last_accel_bias_; }
  const TriadErrors& gyro_errors() const { return gyro_errors_; }
  const TriadErrors& accel_errors() const { return accel_errors_; }
  const ImuVibration& vibration() const { return vibration_; }

 private:
  Eigen::Vector3d Gaussian3();
  Status SimulateSample(int i, uint32_t connection, ros1::BagWriter* writer);

  const proto::SimImuParams& params_;
  const Scenario& scenario_;
  const ImuSchedule schedule_;
  Rng rng_;
  const double rate_;
  const double gyro_sigma_, accel_sigma_, gyro_walk_, accel_walk_;
  // Published value = SI value × this (1 in SI units).
  const double gyro_published_per_si_, accel_published_per_si_;
  Eigen::Vector3d gyro_bias_, accel_bias_;
  Eigen::Vector3d last_gyro_bias_, last_accel_bias_;
  const ImuVibration vibration_;
  TriadErrors gyro_errors_, accel_errors_;
  Eigen::Matrix3d gyro_from_true_, accel_from_true_;  // K_g, K_a
  int next_ = 0;
  double max_yaw_rate_ = 0.0;
  std::string message_;
};

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_IMU_SIMULATOR_H_
