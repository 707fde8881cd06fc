#include "common/imu/gyro_integrator.h"

#include <algorithm>

#include "common/geometry/so3.h"

namespace tiltcal::imu {

using geometry::ExpQuaternion;

GyroIntegrator::GyroIntegrator(const std::vector<ImuReading>& samples,
                               const Eigen::Vector3d& gyro_bias_radps) {
  times_.reserve(samples.size());
  rates_.reserve(samples.size());
  rotations_.reserve(samples.size());
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  for (size_t k = 0; k < samples.size(); ++k) {
    const Eigen::Vector3d w = samples[k].angular_velocity_radps - gyro_bias_radps;
    if (k > 0) {
      const double dt = samples[k].time_s - times_.back();
      q = (q * ExpQuaternion(Eigen::Vector3d(0.5 * (rates_.back() + w) * dt))).normalized();
    }
    times_.push_back(samples[k].time_s);
    rates_.push_back(w);
    rotations_.push_back(q);
  }
}

Eigen::Quaterniond GyroIntegrator::Rotation(double time_s) const {
  if (times_.empty()) return Eigen::Quaterniond::Identity();
  if (time_s <= times_.front()) {
    return (rotations_.front() *
            ExpQuaternion(Eigen::Vector3d(rates_.front() * (time_s - times_.front()))))
        .normalized();
  }
  if (time_s >= times_.back()) {
    return (rotations_.back() *
            ExpQuaternion(Eigen::Vector3d(rates_.back() * (time_s - times_.back()))))
        .normalized();
  }
  const size_t k1 =
      static_cast<size_t>(std::upper_bound(times_.begin(), times_.end(), time_s) - times_.begin());
  const size_t k = k1 - 1;
  const double dt = times_[k1] - times_[k];
  const double s = time_s - times_[k];
  const Eigen::Vector3d w_mid = rates_[k] + (rates_[k1] - rates_[k]) * (0.5 * s / dt);
  return (rotations_[k] * ExpQuaternion(Eigen::Vector3d(w_mid * s))).normalized();
}

Eigen::Quaterniond GyroIntegrator::RelativeRotation(double t1_s, double t2_s) const {
  return (Rotation(t1_s).conjugate() * Rotation(t2_s)).normalized();
}

}  // namespace tiltcal::imu
