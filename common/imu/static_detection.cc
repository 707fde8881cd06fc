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

}  // namespace

std::vector<StaticInterval> DetectStaticIntervals(const std::vector<ImuReading>& samples,
                                                  const StaticDetectionOptions& options) {
  std::vector<StaticInterval> intervals;
  if (samples.size() < 2 || !(options.window_s > 0.0) || !(options.hop_s > 0.0)) {
    return intervals;
  }
  const double t0 = samples.front().time_s;
  const double t_last = samples.back().time_s;
  bool in_run = false;
  double run_begin = 0.0, run_end = 0.0;
  auto close_run = [&] {
    if (in_run && run_end - run_begin >= options.min_duration_s) {
      StaticInterval interval = Statistics(samples, LowerIndex(samples, run_begin),
                                           LowerIndex(samples, run_end));
      interval.found = true;
      interval.begin_s = run_begin;
      interval.end_s = run_end;
      intervals.push_back(interval);
    }
    in_run = false;
  };
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
      close_run();
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
      if (!in_run) run_begin = begin_t;
      in_run = true;
      run_end = end_t;
    } else {
      close_run();
    }
    ++k;
  }
  close_run();
  return intervals;
}

StaticInterval DetectStaticStart(const std::vector<ImuReading>& samples,
                                 const StaticDetectionOptions& options) {
  const std::vector<StaticInterval> intervals = DetectStaticIntervals(samples, options);
  if (!intervals.empty() && intervals.front().begin_index == 0) return intervals.front();
  return StaticInterval();
}

}  // namespace tiltcal::imu
