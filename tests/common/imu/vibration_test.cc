// MeasureImuVibration (common/imu/vibration.h) on synthetic readings: a slow
// turn and sway (the vehicle's motion), white noise, and a vibration of known
// frequency and amplitude. The high-passed RMS must be the vibration's
// A / sqrt(2) (plus the noise in quadrature) and the peak its frequency;
// without vibration the RMS is the noise and the motion does not leak in.

#include <cmath>
#include <optional>
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
  o.low_pass.cutoff_hz = 12.0;
  o.low_pass.span_s = 0.5;
  o.low_pass.max_gap_s = 0.02;
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
  // 0.5 s without readings (100 grid samples): a sample whose filter span
  // reaches into it is left out too (50 on either side).
  const ImuVibration with_gap = MeasureImuVibration(Readings(37.0, 0.0, 0.0, 20.0, 20.5), Options());
  const ImuVibration without = MeasureImuVibration(Readings(37.0, 0.0, 0.0), Options());
  EXPECT_NEAR(with_gap.num_samples, without.num_samples - 200, 2);
  EXPECT_NEAR(with_gap.accel.rms.z(), without.accel.rms.z(), 0.001);
}

// Readings of a 2 Hz motion (gyro) and a 37 Hz vibration (accelerometer),
// stamps jittered by 0.2 ms, a fraction of them missing.
std::vector<ImuReading> MotionAndVibration(double drop_fraction) {
  std::mt19937 rng(9);
  std::normal_distribution<double> jitter(0.0, 2e-4);
  std::uniform_real_distribution<double> drop(0.0, 1.0);
  std::vector<ImuReading> readings;
  for (int i = 0; i < 4000; ++i) {
    if (i > 0 && i < 3999 && drop(rng) < drop_fraction) continue;
    ImuReading r;
    r.time_s = i / kRateHz + jitter(rng);
    const double v = std::sin(2.0 * M_PI * 37.0 * r.time_s);
    r.angular_velocity_radps = Eigen::Vector3d::Constant(0.3 * std::sin(2.0 * M_PI * 2.0 * r.time_s));
    r.linear_acceleration_mps2 = Eigen::Vector3d::Constant(9.81 + 1.5 * v);
    readings.push_back(r);
  }
  return readings;
}

// The low-passed grid against the motion: worst and RMS error of the gyro
// (the 2 Hz motion) and of the accelerometer (the vibration left).
struct LowPassErrors {
  double worst_gyro = 0.0, worst_accel = 0.0, rms_accel = 0.0;
  int valued = 0, grid = 0;
};

LowPassErrors Errors(const ImuGrid& low) {
  LowPassErrors e;
  e.grid = static_cast<int>(low.samples.size());
  for (const std::optional<ImuReading>& r : low.samples) {
    if (!r) continue;
    ++e.valued;
    const double motion = 0.3 * std::sin(2.0 * M_PI * 2.0 * r->time_s);
    e.worst_gyro = std::max(e.worst_gyro, std::abs(r->angular_velocity_radps.x() - motion));
    const double a = r->linear_acceleration_mps2.z() - 9.81;
    e.worst_accel = std::max(e.worst_accel, std::abs(a));
    e.rms_accel += a * a;
  }
  e.rms_accel = std::sqrt(e.rms_accel / std::max(e.valued, 1));
  return e;
}

LowPassOptions TwelveHertz() {
  LowPassOptions o;
  o.cutoff_hz = 12.0;
  o.span_s = 0.5;
  o.max_gap_s = 0.02;
  return o;
}

// Jittered stamps: a 2 Hz motion passes with gain 1 and no delay, a 37 Hz
// vibration does not; decimated, the samples are `step` grid intervals apart.
TEST(ImuLowPass, KeepsTheMotionWithoutDelayAndRemovesTheVibration) {
  const LowPassOptions o = TwelveHertz();
  const std::vector<ImuReading> readings = MotionAndVibration(0.0);
  const ImuGrid low = LowPassImu(ResampleImu(readings, o.max_gap_s), o.cutoff_hz, o.span_s);
  EXPECT_NEAR(low.interval_s, 1.0 / kRateHz, 1e-5);
  const LowPassErrors e = Errors(low);
  EXPECT_EQ(e.valued, e.grid - 100);  // all but the half spans at the ends
  // 2 Hz at 0.3 rad/s: a delay of 1 ms would show as 0.004 rad/s.
  EXPECT_LT(e.worst_gyro, 0.002);
  EXPECT_LT(e.worst_accel, 0.03);  // of 1.5 m/s^2 at 37 Hz

  const std::vector<ImuReading> thinned = LowPassAndDecimateImu(readings, o, 8);
  EXPECT_NEAR(static_cast<double>(thinned.size()), (e.grid - 100) / 8.0, 1.0);
  for (size_t i = 1; i < thinned.size(); ++i) {
    EXPECT_NEAR(thinned[i].time_s - thinned[i - 1].time_s, 8.0 * low.interval_s, 1e-9);
  }
}

// 5 % of the readings missing: what the linear interpolation over a missing
// reading gets wrong of the vibration leaks through there, little overall.
TEST(ImuLowPass, MissingReadingsLeakLittle) {
  const LowPassOptions o = TwelveHertz();
  const LowPassErrors e =
      Errors(LowPassImu(ResampleImu(MotionAndVibration(0.05), o.max_gap_s), o.cutoff_hz, o.span_s));
  EXPECT_GT(e.valued, e.grid / 2);
  EXPECT_LT(e.worst_gyro, 0.01);
  EXPECT_LT(e.rms_accel, 0.1);  // of 1.06 m/s^2 RMS
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
