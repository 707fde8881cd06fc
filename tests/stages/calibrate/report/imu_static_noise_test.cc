// The IMU's noise at rest: readings of known white noise over a static
// start give the ratio of its variance to the model's, times the low-pass
// correlation; the readings outside the window, a constant specific force
// and too short a window do not count.

#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "stages/calibrate/report/imu_static_noise.h"

namespace tiltcal::calibrate {
namespace {

TEST(ImuStaticNoiseTest, RatioOfTheNoiseAtRestToTheModel) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  const double gyro_sigma = 0.002;
  const double accel_sigma = 0.03;
  std::vector<imu::ImuReading> readings;
  for (int i = 0; i < 2000; ++i) {
    imu::ImuReading r;
    r.time_s = 0.01 * i;
    const bool moving = r.time_s >= 10.0;
    for (int a = 0; a < 3; ++a) {
      r.angular_velocity_radps[a] = gyro_sigma * normal(rng) + (moving ? 0.5 * a : 0.0);
      r.linear_acceleration_mps2[a] = accel_sigma * normal(rng) + (a == 2 ? -9.81 : 0.0);
    }
    if (moving) r.linear_acceleration_mps2 += Eigen::Vector3d(1.0, -2.0, 0.5) * (r.time_s - 10.0);
    readings.push_back(r);
  }
  // Model sigmas twice the noise's: variance ratio 1/4, times 2.
  const ImuStaticNoise at_rest =
      MeasureImuStaticNoise(readings, 0.0, 9.995, 2.0 * gyro_sigma, 2.0 * accel_sigma, 2.0);
  EXPECT_EQ(at_rest.samples, 1000);
  EXPECT_NEAR(at_rest.gyro_factor, 0.5, 0.5 * 0.06);
  EXPECT_NEAR(at_rest.accel_factor, 0.5, 0.5 * 0.06);
  // The moving part would count its motion as noise.
  const ImuStaticNoise moving =
      MeasureImuStaticNoise(readings, 0.0, 15.0, 2.0 * gyro_sigma, 2.0 * accel_sigma, 2.0);
  EXPECT_GT(moving.gyro_factor, 10.0);
  EXPECT_GT(moving.accel_factor, 10.0);
  // Too few readings: no measurement.
  const ImuStaticNoise short_window =
      MeasureImuStaticNoise(readings, 0.0, 0.085, 2.0 * gyro_sigma, 2.0 * accel_sigma, 2.0);
  EXPECT_EQ(short_window.samples, 9);
  EXPECT_EQ(short_window.gyro_factor, 0.0);
  EXPECT_EQ(short_window.accel_factor, 0.0);
}

}  // namespace
}  // namespace tiltcal::calibrate
