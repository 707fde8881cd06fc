#include "common/imu/angular_speed_alignment.h"

#include <array>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"

namespace tiltcal::imu {
namespace {

// Angular speed of a vehicle turning irregularly (rad/s): the magnitude of a
// sum of sines of random frequencies (0.1 to 2 rad/s) and phases, so that no
// lag but the true one lines the signals up.
double TrueSpeed(double t) {
  static const std::vector<std::array<double, 3>> terms = [] {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> frequency(0.1, 2.0), phase(0.0, 6.283);
    std::vector<std::array<double, 3>> out;
    for (int i = 0; i < 12; ++i) out.push_back({0.15, frequency(rng), phase(rng)});
    return out;
  }();
  double rate = 0.0;
  for (const auto& [amplitude, frequency, phase] : terms) {
    rate += amplitude * std::sin(frequency * t + phase);
  }
  return std::abs(rate);
}

// Gyro at 200 Hz on the IMU clock (scale, noise); the reference at 10 Hz on
// the LiDAR clock, whose stamp t_l happened at IMU time t_l + tau.
void MakeSignals(double tau, double gyro_scale, double duration_s, std::vector<TimedValue>* gyro,
                 std::vector<TimedValue>* reference) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.01);
  gyro->clear();
  reference->clear();
  for (int k = 0; k * 0.005 <= duration_s; ++k) {
    const double t = k * 0.005;
    gyro->push_back({t, gyro_scale * (TrueSpeed(t) + noise(rng))});
  }
  // LiDAR stamps cover the same physical span: t_l = t − tau.
  for (int k = 0; k * 0.1 <= duration_s; ++k) {
    const double t = k * 0.1;
    reference->push_back({t - tau, TrueSpeed(t) + noise(rng)});
  }
}

AngularSpeedAlignmentOptions Options(double max_offset_s) {
  AngularSpeedAlignmentOptions options;
  options.max_time_offset_s = max_offset_s;
  options.grid_step_s = 0.005;
  options.min_overlap_s = 5.0;
  options.min_reference_speed = 0.05;
  return options;
}

struct Case {
  double tau_s;
  double gyro_scale;
  double max_offset_s;
};

class AlignAngularSpeedsTest : public ::testing::TestWithParam<Case> {};

TEST_P(AlignAngularSpeedsTest, RecoversOffsetAndScale) {
  const Case c = GetParam();
  std::vector<TimedValue> gyro, reference;
  MakeSignals(c.tau_s, c.gyro_scale, 40.0, &gyro, &reference);
  AngularSpeedAlignment alignment;
  const Status status = AlignAngularSpeeds(gyro, reference, Options(c.max_offset_s), &alignment);
  ASSERT_TRUE(status.ok()) << status.message();
  // A coarse τ: a few ms (the noise of the peak), well inside the 15 ms the
  // fine solve may move τ per round.
  EXPECT_NEAR(alignment.time_offset_s, c.tau_s, 0.005);
  EXPECT_NEAR(alignment.scale / c.gyro_scale, 1.0, 0.03);
  EXPECT_GT(alignment.correlation, 0.9);
  EXPECT_LT(alignment.second_peak_correlation, alignment.correlation - 0.2);
  EXPECT_FALSE(alignment.at_search_bound);
}

INSTANTIATE_TEST_SUITE_P(
    OffsetsAndUnits, AlignAngularSpeedsTest,
    ::testing::Values(Case{0.0125, 1.0, 1.0}, Case{0.080, 1.0, 1.0}, Case{-0.3, 1.0, 1.0},
                      Case{2.0, 1.0, 10.0}, Case{0.080, geometry::kDegPerRad, 1.0},
                      Case{-7.3, geometry::kDegPerRad, 20.0}));

TEST(AlignAngularSpeeds, OffsetBeyondTheWindowEndsAtTheBoundOrAWeakPeak) {
  std::vector<TimedValue> gyro, reference;
  MakeSignals(2.0, 1.0, 40.0, &gyro, &reference);
  AngularSpeedAlignment alignment;
  ASSERT_TRUE(AlignAngularSpeeds(gyro, reference, Options(1.0), &alignment).ok());
  // The true lag is outside ±1 s: the best lag in the window is no real match.
  EXPECT_TRUE(alignment.at_search_bound || alignment.correlation < 0.5)
      << "tau " << alignment.time_offset_s << " r " << alignment.correlation;
}

TEST(AlignAngularSpeeds, NoOverlapNamesBothSpans) {
  std::vector<TimedValue> gyro, reference;
  MakeSignals(600.0, 1.0, 40.0, &gyro, &reference);  // clocks ten minutes apart
  AngularSpeedAlignment alignment;
  const Status status = AlignAngularSpeeds(gyro, reference, Options(1.0), &alignment);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("overlap by less than 5 s"), std::string::npos)
      << status.message();
  EXPECT_NE(status.message().find("the reference (-600.000"), std::string::npos)
      << status.message();
}

TEST(AlignAngularSpeeds, NoRotationIsAnError) {
  std::vector<TimedValue> gyro, reference;
  for (int k = 0; k < 400; ++k) gyro.push_back({k * 0.005, 0.0});
  for (int k = 0; k < 20; ++k) reference.push_back({k * 0.1, 0.0});
  AngularSpeedAlignment alignment;
  AngularSpeedAlignmentOptions options = Options(0.5);
  options.min_overlap_s = 1.0;
  const Status status = AlignAngularSpeeds(gyro, reference, options, &alignment);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("did not turn"), std::string::npos) << status.message();
}

TEST(AlignAngularSpeeds, RejectsBadInput) {
  std::vector<TimedValue> gyro, reference;
  MakeSignals(0.0, 1.0, 10.0, &gyro, &reference);
  AngularSpeedAlignment alignment;
  std::vector<TimedValue> unordered = reference;
  std::swap(unordered[3], unordered[4]);
  EXPECT_FALSE(AlignAngularSpeeds(gyro, unordered, Options(1.0), &alignment).ok());
  EXPECT_FALSE(AlignAngularSpeeds(gyro, {reference[0], reference[1]}, Options(1.0), &alignment)
                   .ok());
  AngularSpeedAlignmentOptions zero_step = Options(1.0);
  zero_step.grid_step_s = 0.0;
  EXPECT_FALSE(AlignAngularSpeeds(gyro, reference, zero_step, &alignment).ok());
}

}  // namespace
}  // namespace tiltcal::imu
