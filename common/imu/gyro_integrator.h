#ifndef TILTCAL_COMMON_IMU_GYRO_INTEGRATOR_H_
#define TILTCAL_COMMON_IMU_GYRO_INTEGRATOR_H_

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/imu/imu_reading.h"

namespace tiltcal::imu {

// C_ab(t) by integrating the bias-corrected gyro (a = the IMU frame at the
// first sample, so C_ab(t_0) = 1). With w_k = ω_m,k − b_g, dt = t_{k+1} − t_k:
//   C_ab(t_{k+1}) = C_ab(t_k) Exp(½ (w_k + w_{k+1}) dt)
// and inside an interval, with w linear in time,
//   C_ab(t_k + s) = C_ab(t_k) Exp(w(t_k + s/2) s),
// which reproduces the step rule at s = dt. Before the first / after the last
// sample the rotation is extrapolated at the first / last rate.
class GyroIntegrator {
 public:
  GyroIntegrator() = default;
  // Samples must be valid (ValidateImuReadings).
  GyroIntegrator(const std::vector<ImuReading>& samples, const Eigen::Vector3d& gyro_bias_radps);

  // C_ab(t) as a unit quaternion (maps b at time t to a).
  Eigen::Quaterniond Rotation(double time_s) const;
  // C_{b(t1) b(t2)} = C_ab(t1)^T C_ab(t2).
  Eigen::Quaterniond RelativeRotation(double t1_s, double t2_s) const;

  double begin_s() const { return times_.empty() ? 0.0 : times_.front(); }
  double end_s() const { return times_.empty() ? 0.0 : times_.back(); }
  bool empty() const { return times_.empty(); }

 private:
  std::vector<double> times_;
  std::vector<Eigen::Vector3d> rates_;         // bias-corrected, rad/s
  std::vector<Eigen::Quaterniond> rotations_;  // C_ab(t_k)
};

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_GYRO_INTEGRATOR_H_
