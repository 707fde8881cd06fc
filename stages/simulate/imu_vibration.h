#ifndef TILTCAL_STAGES_SIMULATE_IMU_VIBRATION_H_
#define TILTCAL_STAGES_SIMULATE_IMU_VIBRATION_H_

#include <cstdint>

#include <Eigen/Core>

#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal::simulate {

// Engine and wheel vibration as the IMU feels it (SimImuVibration), added to
// the true angular rate and specific force in the IMU frame b before the
// triad errors, bias and noise:
//   ω_vib,i(t) = A_ω w(t) sin(2π f t + ψ_i),   f_vib,i(t) = A_f w(t) sin(2π f t + φ_i),
// i = x, y, z, t in s since the first IMU sample, phases ψ_i, φ_i uniform in
// [0, 2π) from the vibration stream of the seed (random.h). w(t) = 1
// (`ALWAYS`: an idling engine during the static start too) or σ'(t), the
// path rate of the trajectory (`WHILE_MOVING`: 0 while static, ramping to 1
// with the vehicle). The IMU samples the sinusoid at its own rate without an
// anti-aliasing filter: a frequency f above rate/2 shows at
// |f − round(f / rate) · rate|. The vibration moves neither the body nor the
// LiDAR (that is SimTrajectoryParams' vibration_roll_deg / pitch).
class ImuVibration {
 public:
  ImuVibration(const proto::SimImuVibration& params, uint64_t seed);

  // False when both amplitudes are 0 (Add then changes nothing).
  bool enabled() const { return enabled_; }
  // Adds the vibration at time t with path rate `moving_rate` = σ'(t).
  void Add(double t, double moving_rate, Eigen::Vector3d* angular_rate_b,
           Eigen::Vector3d* specific_force_b) const;

  const Eigen::Vector3d& gyro_phase_rad() const { return gyro_phase_rad_; }    // ψ
  const Eigen::Vector3d& accel_phase_rad() const { return accel_phase_rad_; }  // φ

 private:
  double frequency_hz_, gyro_amplitude_radps_, accel_amplitude_mps2_;
  bool while_moving_only_;
  bool enabled_;
  Eigen::Vector3d gyro_phase_rad_, accel_phase_rad_;
};

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_IMU_VIBRATION_H_
