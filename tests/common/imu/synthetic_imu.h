#ifndef TILTCAL_TESTS_COMMON_IMU_SYNTHETIC_IMU_H_
#define TILTCAL_TESTS_COMMON_IMU_SYNTHETIC_IMU_H_

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "common/imu/imu_reading.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::imu::testing {

// IMU readings of a body with angular velocity `omega(t)` (body frame),
// starting at attitude C_w_b0 in a world with gravity g_w, no translation
// (specific force = −C_wb^T g_w), plus gyro bias and white noise. The true
// attitude C_wb at each sample is returned in *attitudes.
inline std::vector<ImuReading> SyntheticImu(double rate_hz, double duration_s,
                                            const std::function<Eigen::Vector3d(double)>& omega,
                                            const Eigen::Quaterniond& c_w_b0,
                                            const Eigen::Vector3d& g_w,
                                            const Eigen::Vector3d& gyro_bias,
                                            double gyro_noise, double accel_noise,
                                            std::vector<Eigen::Quaterniond>* attitudes) {
  std::mt19937 rng(42);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::vector<ImuReading> readings;
  Eigen::Quaterniond c_wb = c_w_b0;
  const double dt = 1.0 / rate_hz;
  const int steps = 20;  // fine integration of the truth between samples
  for (int k = 0; k * dt <= duration_s + 1e-12; ++k) {
    const double t = k * dt;
    if (k > 0) {
      for (int j = 0; j < steps; ++j) {
        const double tm = t - dt + (j + 0.5) * dt / steps;
        c_wb = (c_wb * geometry::ExpQuaternion(Eigen::Vector3d(omega(tm) * dt / steps)))
                   .normalized();
      }
    }
    ImuReading r;
    r.time_s = t;
    r.angular_velocity_radps = omega(t) + gyro_bias +
                               gyro_noise * tiltcal::testing::RandomVector3(n01, rng);
    r.linear_acceleration_mps2 = -(c_wb.conjugate() * g_w) +
                                 accel_noise * tiltcal::testing::RandomVector3(n01, rng);
    readings.push_back(r);
    if (attitudes != nullptr) attitudes->push_back(c_wb);
  }
  return readings;
}

}  // namespace tiltcal::imu::testing

#endif  // TILTCAL_TESTS_COMMON_IMU_SYNTHETIC_IMU_H_
