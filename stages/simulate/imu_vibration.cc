#include "stages/simulate/imu_vibration.h"

#include <cmath>

#include "common/geometry/angles.h"
#include "stages/simulate/random.h"

namespace tiltcal::simulate {

using geometry::kTwoPi;

ImuVibration::ImuVibration(const proto::SimImuVibration& p, uint64_t seed)
    : frequency_hz_(p.frequency_hz()),
      gyro_amplitude_radps_(p.gyro_amplitude_radps()),
      accel_amplitude_mps2_(p.accel_amplitude_mps2()),
      while_moving_only_(p.when() == proto::SimImuVibration::WHILE_MOVING),
      enabled_(p.gyro_amplitude_radps() > 0 || p.accel_amplitude_mps2() > 0) {
  Rng rng(seed, kImuVibrationStream);
  for (int a = 0; a < 3; ++a) gyro_phase_rad_[a] = rng.Uniform(0.0, kTwoPi);
  for (int a = 0; a < 3; ++a) accel_phase_rad_[a] = rng.Uniform(0.0, kTwoPi);
}

void ImuVibration::Add(double t, double moving_rate, Eigen::Vector3d* angular_rate_b,
                       Eigen::Vector3d* specific_force_b) const {
  if (!enabled_) return;
  const double weight = while_moving_only_ ? moving_rate : 1.0;
  const double wt = kTwoPi * frequency_hz_ * t;
  for (int a = 0; a < 3; ++a) {
    (*angular_rate_b)[a] += gyro_amplitude_radps_ * weight * std::sin(wt + gyro_phase_rad_[a]);
    (*specific_force_b)[a] += accel_amplitude_mps2_ * weight * std::sin(wt + accel_phase_rad_[a]);
  }
}

}  // namespace tiltcal::simulate
