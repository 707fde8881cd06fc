#include "common/imu/static_detection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "tests/common/imu/synthetic_imu.h"
#include "tests/common/imu/imu_test_options.h"

namespace tiltcal::imu {
namespace {

using testing::StaticDetectionTestOptions;

// Still for [0, 3) s, turning for [3, 6) s, still for [6, 8) s, turning after.
Eigen::Vector3d Omega(double t) {
  const bool moving = (t >= 3.0 && t < 6.0) || t >= 8.0;
  return moving ? Eigen::Vector3d(0.1, -0.2, 0.5 + 0.3 * std::sin(3 * t)) : Eigen::Vector3d::Zero();
}

TEST(StaticDetection, FindsEveryStillIntervalWithItsMeans) {
  const Eigen::Vector3d bias(0.002, -0.001, 0.003);
  const auto readings = testing::SyntheticImu(200, 10, Omega, Eigen::Quaterniond::Identity(),
                                              {0, 0, -9.81}, bias, 0.001, 0.01, nullptr);
  StaticDetectionOptions options = StaticDetectionTestOptions();
  const auto intervals = DetectStaticIntervals(readings, options);
  ASSERT_EQ(intervals.size(), 2u);
  EXPECT_NEAR(intervals[0].begin_s, 0.0, 1e-9);
  EXPECT_NEAR(intervals[0].end_s, 3.0, options.hop_s + 0.01);
  EXPECT_LE(intervals[0].end_s, 3.0 + 1e-9);
  EXPECT_GE(intervals[1].begin_s, 6.0 - 1e-9);
  EXPECT_NEAR(intervals[1].begin_s, 6.0, options.hop_s + 0.01);
  EXPECT_NEAR(intervals[1].end_s, 8.0, options.hop_s + 0.01);
  // Mean gyro = bias within noise / sqrt(n); mean accel = −g.
  EXPECT_LT((intervals[0].mean_gyro_radps - bias).norm(), 3e-4);
  EXPECT_LT((intervals[0].mean_accel_mps2 - Eigen::Vector3d(0, 0, 9.81)).norm(), 3e-3);
  EXPECT_NEAR(intervals[0].accel_std_mps2, 0.01, 0.002);

  const StaticInterval start = DetectStaticStart(readings, options);
  ASSERT_TRUE(start.found);
  EXPECT_EQ(start.begin_index, 0u);
  EXPECT_EQ(start.end_index, intervals[0].end_index);
}

TEST(StaticDetection, NoStaticStartWhenMovingFromTheBeginning) {
  const auto readings = testing::SyntheticImu(
      200, 4, [](double) { return Eigen::Vector3d(0, 0, 0.3); }, Eigen::Quaterniond::Identity(),
      {0, 0, -9.81}, Eigen::Vector3d::Zero(), 0.001, 0.01, nullptr);
  // A steady turn is not still.
  EXPECT_TRUE(DetectStaticIntervals(readings, StaticDetectionTestOptions()).empty());
  EXPECT_FALSE(DetectStaticStart(readings, StaticDetectionTestOptions()).found);
}

TEST(StaticDetection, ShortStillnessIsIgnored) {
  const auto readings = testing::SyntheticImu(
      200, 4, [](double t) { return t < 0.7 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0, 0, 1); },
      Eigen::Quaterniond::Identity(), {0, 0, -9.81}, Eigen::Vector3d::Zero(), 0.001, 0.01,
      nullptr);
  EXPECT_FALSE(DetectStaticStart(readings, StaticDetectionTestOptions()).found);
}

// The detector before it stepped over empty windows: every window of the
// span, one hop at a time (O(span / hop)). The reference for the tests below.
std::vector<StaticInterval> EveryWindowReference(const std::vector<ImuReading>& samples,
                                                 const StaticDetectionOptions& options) {
  std::vector<StaticInterval> intervals;
  auto lower = [&](double t) {
    return static_cast<size_t>(
        std::lower_bound(samples.begin(), samples.end(), t,
                         [](const ImuReading& s, double v) { return s.time_s < v; }) -
        samples.begin());
  };
  auto stats = [&](size_t begin, size_t end) {
    StaticInterval s;
    s.begin_index = begin;
    s.end_index = end;
    const double n = static_cast<double>(end - begin);
    for (size_t i = begin; i < end; ++i) {
      s.mean_gyro_radps += samples[i].angular_velocity_radps / n;
      s.mean_accel_mps2 += samples[i].linear_acceleration_mps2 / n;
    }
    Eigen::Vector3d gv = Eigen::Vector3d::Zero(), av = Eigen::Vector3d::Zero();
    for (size_t i = begin; i < end; ++i) {
      gv += (samples[i].angular_velocity_radps - s.mean_gyro_radps).cwiseAbs2();
      av += (samples[i].linear_acceleration_mps2 - s.mean_accel_mps2).cwiseAbs2();
    }
    s.gyro_std_radps = std::sqrt(gv.maxCoeff() / n);
    s.accel_std_mps2 = std::sqrt(av.maxCoeff() / n);
    return s;
  };
  bool in_run = false;
  double run_begin = 0, run_end = 0;
  auto close_run = [&] {
    if (in_run && run_end - run_begin >= options.min_duration_s) {
      StaticInterval interval = stats(lower(run_begin), lower(run_end));
      interval.begin_s = run_begin;
      interval.end_s = run_end;
      intervals.push_back(interval);
    }
    in_run = false;
  };
  const double t0 = samples.front().time_s;
  for (int64_t k = 0;; ++k) {
    const double begin_t = t0 + static_cast<double>(k) * options.hop_s;
    const double end_t = begin_t + options.window_s;
    if (end_t > samples.back().time_s + 1e-12) break;
    const size_t begin = lower(begin_t), end = lower(end_t);
    bool is_static = false;
    if (end >= begin + 2) {
      const StaticInterval s = stats(begin, end);
      is_static = s.gyro_std_radps <= options.max_gyro_std_radps &&
                  s.accel_std_mps2 <= options.max_accel_std_mps2 &&
                  s.mean_gyro_radps.norm() <= options.max_gyro_mean_radps;
    }
    if (is_static) {
      if (!in_run) run_begin = begin_t;
      in_run = true;
      run_end = end_t;
    } else {
      close_run();
    }
  }
  close_run();
  return intervals;
}

void ExpectSameIntervals(const std::vector<StaticInterval>& a,
                         const std::vector<StaticInterval>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].begin_index, b[i].begin_index) << i;
    EXPECT_EQ(a[i].end_index, b[i].end_index) << i;
    EXPECT_EQ(a[i].begin_s, b[i].begin_s) << i;
    EXPECT_EQ(a[i].end_s, b[i].end_s) << i;
  }
}

// Still 3 s, turning 3 s, still 2 s, turning, as above.
std::vector<ImuReading> StillAndTurning(double duration_s) {
  return testing::SyntheticImu(200, duration_s, Omega, Eigen::Quaterniond::Identity(),
                               {0, 0, -9.81}, Eigen::Vector3d::Zero(), 0.001, 0.01, nullptr);
}

TEST(StaticDetection, GapsGiveTheSameIntervalsAsEveryWindow) {
  // Two recordings 500 s apart (10^4 hops in the gap): the windows without
  // samples that are stepped over change nothing.
  std::vector<ImuReading> readings = StillAndTurning(9);
  for (ImuReading r : StillAndTurning(9)) {
    r.time_s += 500.0;
    readings.push_back(r);
  }
  const auto intervals = DetectStaticIntervals(readings, StaticDetectionTestOptions());
  EXPECT_EQ(intervals.size(), 4u);
  ExpectSameIntervals(intervals, EveryWindowReference(readings, StaticDetectionTestOptions()));
}

TEST(StaticDetection, StampFarInTheFutureIsBoundedWork) {
  // One sample at the end of uint32 seconds (2^32 − 1 s: 4·10^10 hops of
  // 0.1 s, hours for a loop over every window): the same intervals as with
  // that sample 100 s after the others, where every window can be tried.
  std::vector<ImuReading> readings = StillAndTurning(9);
  readings.push_back(readings.back());
  readings.back().time_s = 100.0;
  const auto reference = EveryWindowReference(readings, StaticDetectionTestOptions());
  EXPECT_EQ(reference.size(), 2u);
  readings.back().time_s = 4294967295.0;
  ASSERT_TRUE(ValidateImuReadings(readings).ok());
  ExpectSameIntervals(DetectStaticIntervals(readings, StaticDetectionTestOptions()), reference);
}

// The still-and-turning readings of FindsEveryStillIntervalWithItsMeans with
// an engine's vibration on every sample: 0.3 m/s² and 0.02 rad/s at 23.7 Hz.
std::vector<ImuReading> VibratingStillAndTurning(const Eigen::Vector3d& bias) {
  std::vector<ImuReading> readings = testing::SyntheticImu(
      200, 10, Omega, Eigen::Quaterniond::Identity(), {0, 0, -9.81}, bias, 0.001, 0.01, nullptr);
  const double w = 2.0 * M_PI * 23.7;
  for (ImuReading& r : readings) {
    r.linear_acceleration_mps2 += 0.3 * Eigen::Vector3d(std::sin(w * r.time_s),
                                                         std::cos(w * r.time_s),
                                                         std::sin(w * r.time_s + 1.0));
    r.angular_velocity_radps += 0.02 * Eigen::Vector3d(std::cos(w * r.time_s), 0.0,
                                                       std::sin(w * r.time_s));
  }
  return readings;
}

StaticDetectionOptions LowPassedTestOptions() {
  StaticDetectionOptions options = StaticDetectionTestOptions();
  options.low_pass.cutoff_hz = 5.0;
  options.low_pass.span_s = 0.5;
  options.low_pass.max_gap_s = 0.1;
  return options;
}

TEST(StaticDetection, VibrationHidesStillnessFromTheRecordedReadings) {
  // The test below is needed: on the readings as recorded a vibrating IMU
  // never looks still.
  const auto readings = VibratingStillAndTurning(Eigen::Vector3d::Zero());
  EXPECT_TRUE(DetectStaticIntervals(readings, StaticDetectionTestOptions()).empty());
}

TEST(StaticDetection, LowPassFindsTheStillIntervalsOfAVibratingImu) {
  const Eigen::Vector3d bias(0.002, -0.001, 0.003);
  const auto readings = VibratingStillAndTurning(bias);
  const StaticDetectionOptions options = LowPassedTestOptions();
  const auto intervals = DetectStaticIntervals(readings, options);
  ASSERT_EQ(intervals.size(), 2u);
  // The static start begins at the first reading (the filter's half span
  // before its first low-passed sample is given to the run that reaches it).
  EXPECT_EQ(intervals[0].begin_index, 0u);
  EXPECT_NEAR(intervals[0].begin_s, 0.0, 1e-9);
  // The low-pass spreads the motion's onset by at most its half span: the
  // intervals end no later than the truth and not much earlier.
  EXPECT_LE(intervals[0].end_s, 3.0 + 1e-9);
  EXPECT_GE(intervals[0].end_s, 3.0 - 0.25 - options.hop_s);
  EXPECT_GE(intervals[1].begin_s, 6.0 - 1e-9);
  EXPECT_LE(intervals[1].begin_s, 6.0 + 0.25 + options.hop_s);
  EXPECT_LE(intervals[1].end_s, 8.0 + 1e-9);
  EXPECT_GE(intervals[1].end_s, 8.0 - 0.25 - options.hop_s);
  // The means are the recorded readings': the vibration averages out.
  EXPECT_LT((intervals[0].mean_gyro_radps - bias).norm(), 3e-4);
  EXPECT_LT((intervals[0].mean_accel_mps2 - Eigen::Vector3d(0, 0, 9.81)).norm(), 3e-3);
  EXPECT_TRUE(DetectStaticStart(readings, options).found);
}

TEST(StaticDetection, LowPassKeepsTheStillIntervalsOfACleanImu) {
  const auto readings = testing::SyntheticImu(200, 10, Omega, Eigen::Quaterniond::Identity(),
                                              {0, 0, -9.81}, Eigen::Vector3d::Zero(), 0.001,
                                              0.01, nullptr);
  const auto intervals = DetectStaticIntervals(readings, LowPassedTestOptions());
  ASSERT_EQ(intervals.size(), 2u);
  EXPECT_EQ(intervals[0].begin_index, 0u);
  EXPECT_GE(intervals[0].end_s, 2.65);
  EXPECT_LE(intervals[0].end_s, 3.0 + 1e-9);
}

TEST(ImuReadings, ValidationNamesTheSample) {
  std::vector<ImuReading> readings(3);
  readings[1].time_s = 0.1;
  readings[2].time_s = 0.1;
  const Status status = ValidateImuReadings(readings);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("IMU sample 2"), std::string::npos) << status.message();
  readings[2].time_s = 0.2;
  readings[1].angular_velocity_radps.x() = NAN;
  EXPECT_NE(ValidateImuReadings(readings).message().find("IMU sample 1: non-finite"),
            std::string::npos);
}

}  // namespace
}  // namespace tiltcal::imu
