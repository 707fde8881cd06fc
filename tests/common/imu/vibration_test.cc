// MeasureImuVibration (common/imu/vibration.h) on synthetic readings: a slow
// turn and sway (the vehicle's motion), white noise, and a vibration of known
// frequency and amplitude. The high-passed RMS must be the vibration's
// A / sqrt(2) (plus the noise in quadrature) and the peak its frequency;
// without vibration the RMS is the noise and the motion does not leak in.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "common/imu/vibration.h"

namespace tiltcal::imu {
namespace {

constexpr double kRateHz = 200.0;

// 40 s at 200 Hz: yaw rate 0.4 sin(0.3 t), a 3 Hz sway of 0.03 rad/s and
// 0.2 m/s², gravity on z; plus white noise and the vibration (A_g, A_a at
// f Hz, a phase per axis); readings in [drop_from_s, drop_to_s) left out.
std::vector<ImuReading> Readings(double vibration_hz, double gyro_amplitude,
                                 double accel_amplitude, double drop_from_s = -1.0,
                                 double drop_to_s = -1.0) {
  std::mt19937 rng(5);
  std::normal_distribution<double> gyro_noise(0.0, 0.002), accel_noise(0.0, 0.014);
  std::vector<ImuReading> out;
  for (int i = 0; i < static_cast<int>(40.0 * kRateHz); ++i) {
    const double t = i / kRateHz;
    if (t >= drop_from_s && t < drop_to_s) continue;
    ImuReading r;
    r.time_s = t;
    const double sway = std::sin(2.0 * M_PI * 3.0 * t);
    for (int a = 0; a < 3; ++a) {
      const double v = std::sin(2.0 * M_PI * vibration_hz * t + 1.1 * a);
      r.angular_velocity_radps[a] = gyro_amplitude * v + gyro_noise(rng) + 0.03 * sway;
      r.linear_acceleration_mps2[a] = accel_amplitude * v + accel_noise(rng) + 0.2 * sway;
    }
    r.angular_velocity_radps.z() += 0.4 * std::sin(0.3 * t);
    r.linear_acceleration_mps2.z() += 9.81;
    out.push_back(r);
  }
  return out;
}

VibrationOptions Options() {
  VibrationOptions o;
  o.cutoff_hz = 12.0;
  o.filter_span_s = 0.5;
  o.spectrum_segment_s = 2.0;
  o.max_segments = 64;
  return o;
}

TEST(ImuVibration, FindsAmplitudeAndFrequencyOfAVibration) {
  for (const double hz : {23.0, 37.0, 61.5}) {
    const ImuVibration v = MeasureImuVibration(Readings(hz, 0.05, 1.5), Options());
    EXPECT_NEAR(v.sample_rate_hz, kRateHz, 1e-6);
    EXPECT_GT(v.num_segments, 10);
    for (int a = 0; a < 3; ++a) {
      // Above the transition the high-pass passes a sinusoid whole; the
      // noise adds in quadrature.
      EXPECT_NEAR(v.accel.rms[a], std::hypot(1.5 / std::sqrt(2.0), 0.014), 0.01)
          << hz << " Hz, axis " << a;
      EXPECT_NEAR(v.gyro.rms[a], std::hypot(0.05 / std::sqrt(2.0), 0.002), 0.0005)
          << hz << " Hz, axis " << a;
    }
    EXPECT_NEAR(v.accel.peak_frequency_hz, hz, 0.5);
    EXPECT_NEAR(v.gyro.peak_frequency_hz, hz, 0.5);
  }
}

TEST(ImuVibration, WithoutVibrationTheRmsIsTheNoiseNotTheMotion) {
  const ImuVibration v = MeasureImuVibration(Readings(37.0, 0.0, 0.0), Options());
  for (int a = 0; a < 3; ++a) {
    // White noise passes as the part of its band above the cut-off
    // (sqrt(1 - 12 / 100) of its sigma 0.002, 0.014); the 3 Hz sway of 0.03
    // rad/s and 0.2 m/s^2 not at all.
    EXPECT_NEAR(v.gyro.rms[a], 0.002 * std::sqrt(0.88), 0.0001);
    EXPECT_NEAR(v.accel.rms[a], 0.014 * std::sqrt(0.88), 0.0007);
  }
}

TEST(ImuVibration, AGapIsLeftOutNotMeasured) {
  // 0.5 s without readings (100 of them): a filter span reaching into it is
  // left out too (50 samples on either side).
  const ImuVibration with_gap = MeasureImuVibration(Readings(37.0, 0.0, 0.0, 20.0, 20.5), Options());
  const ImuVibration without = MeasureImuVibration(Readings(37.0, 0.0, 0.0), Options());
  EXPECT_NEAR(with_gap.num_samples, without.num_samples - 200, 1);
  EXPECT_NEAR(with_gap.accel.rms.z(), without.accel.rms.z(), 0.001);
}

TEST(ImuVibration, TooFewReadingsGiveNothing) {
  std::vector<ImuReading> few(Readings(37.0, 0.05, 1.5));
  few.resize(5);
  const ImuVibration v = MeasureImuVibration(few, Options());
  EXPECT_EQ(v.num_samples, 0);
  EXPECT_EQ(v.accel.peak_frequency_hz, 0.0);
}

}  // namespace
}  // namespace tiltcal::imu
