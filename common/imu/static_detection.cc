#include "common/imu/static_detection.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <optional>

#include "common/checked_conversion.h"

namespace tiltcal::imu {

namespace {

// First index with time >= t.
size_t LowerIndex(const std::vector<ImuReading>& samples, double t) {
  return static_cast<size_t>(
      std::lower_bound(samples.begin(), samples.end(), t,
                       [](const ImuReading& s, double value) { return s.time_s < value; }) -
      samples.begin());
}

// Means and largest per-axis standard deviations over samples [begin, end).
StaticInterval Statistics(const std::vector<ImuReading>& samples, size_t begin, size_t end) {
  StaticInterval s;
  s.begin_index = begin;
  s.end_index = end;
  const double n = static_cast<double>(end - begin);
  for (size_t i = begin; i < end; ++i) {
    s.mean_gyro_radps += samples[i].angular_velocity_radps;
    s.mean_accel_mps2 += samples[i].linear_acceleration_mps2;
  }
  s.mean_gyro_radps /= n;
  s.mean_accel_mps2 /= n;
  Eigen::Vector3d gyro_var = Eigen::Vector3d::Zero(), accel_var = Eigen::Vector3d::Zero();
  for (size_t i = begin; i < end; ++i) {
    gyro_var += (samples[i].angular_velocity_radps - s.mean_gyro_radps).cwiseAbs2();
    accel_var += (samples[i].linear_acceleration_mps2 - s.mean_accel_mps2).cwiseAbs2();
  }
  s.gyro_std_radps = std::sqrt(gyro_var.maxCoeff() / n);
  s.accel_std_mps2 = std::sqrt(accel_var.maxCoeff() / n);
  return s;
}

// A maximal run of static windows, [begin_s, end_s].
struct StaticRun {
  double begin_s = 0.0;
  double end_s = 0.0;
};

// The runs of static windows of `samples` (the window tests of
// DetectStaticIntervals), in time order, whatever their duration.
std::vector<StaticRun> FindStaticRuns(const std::vector<ImuReading>& samples,
                                      const StaticDetectionOptions& options) {
  std::vector<StaticRun> runs;
  if (samples.size() < 2 || !(options.window_s > 0.0) || !(options.hop_s > 0.0)) return runs;
  const double t0 = samples.front().time_s;
  const double t_last = samples.back().time_s;
  bool in_run = false;
  // Windows holding fewer than two samples are never static; the loop jumps
  // over them to the first window that can reach the next sample, so the
  // work is bounded by the samples (times window_s / hop_s), not by the span
  // of the stamps over hop_s.
  for (int64_t k = 0;;) {
    const double begin_t = t0 + static_cast<double>(k) * options.hop_s;
    const double end_t = begin_t + options.window_s;
    if (end_t > t_last + 1e-12) break;
    const size_t begin = LowerIndex(samples, begin_t);
    const size_t end = LowerIndex(samples, end_t);
    if (end < begin + 2) {  // too sparse to judge
      in_run = false;
      // First window whose end reaches the sample after samples[begin].
      const double next_t = samples[std::min(begin + 1, samples.size() - 1)].time_s;
      const double k_reach = std::floor((next_t - options.window_s - t0) / options.hop_s);
      const std::optional<int64_t> k_next = CheckedTruncate<int64_t>(k_reach);
      if (!k_next) break;  // beyond any window index: past the last sample
      k = std::max(*k_next, k + 1);
      continue;
    }
    const StaticInterval s = Statistics(samples, begin, end);
    const bool is_static = s.gyro_std_radps <= options.max_gyro_std_radps &&
                           s.accel_std_mps2 <= options.max_accel_std_mps2 &&
                           s.mean_gyro_radps.norm() <= options.max_gyro_mean_radps;
    if (is_static) {
      if (!in_run) runs.push_back({begin_t, end_t});
      in_run = true;
      runs.back().end_s = end_t;
    } else {
      in_run = false;
    }
    ++k;
  }
  return runs;
}

// The runs found on the low-passed readings, with a run that reaches (within
// a hop) the edge the filter's half span left out extended to the readings'
// first or last time.
std::vector<StaticRun> FindLowPassedStaticRuns(const std::vector<ImuReading>& samples,
                                               const StaticDetectionOptions& options) {
  const std::vector<ImuReading> low = LowPassAndDecimateImu(samples, options.low_pass, 1);
  std::vector<StaticRun> runs = FindStaticRuns(low, options);
  if (runs.empty()) return runs;
  if (runs.front().begin_s <= low.front().time_s + 1e-9) {
    runs.front().begin_s = samples.front().time_s;
  }
  if (runs.back().end_s >= low.back().time_s - options.hop_s) {
    runs.back().end_s = samples.back().time_s;
  }
  return runs;
}

}  // namespace

std::vector<StaticInterval> DetectStaticIntervals(const std::vector<ImuReading>& samples,
                                                  const StaticDetectionOptions& options) {
  const std::vector<StaticRun> runs = options.low_pass.cutoff_hz > 0.0
                                          ? FindLowPassedStaticRuns(samples, options)
                                          : FindStaticRuns(samples, options);
  std::vector<StaticInterval> intervals;
  for (const StaticRun& run : runs) {
    if (run.end_s - run.begin_s < options.min_duration_s) continue;
    StaticInterval interval =
        Statistics(samples, LowerIndex(samples, run.begin_s), LowerIndex(samples, run.end_s));
    interval.found = true;
    interval.begin_s = run.begin_s;
    interval.end_s = run.end_s;
    intervals.push_back(interval);
  }
  return intervals;
}

StaticInterval DetectStaticStart(const std::vector<ImuReading>& samples,
                                 const StaticDetectionOptions& options) {
  const std::vector<StaticInterval> intervals = DetectStaticIntervals(samples, options);
  if (!intervals.empty() && intervals.front().begin_index == 0) return intervals.front();
  return StaticInterval();
}

}  // namespace tiltcal::imu
