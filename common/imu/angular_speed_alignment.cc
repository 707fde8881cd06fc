#include "common/imu/angular_speed_alignment.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace tiltcal::imu {

namespace {

// `series` at time t by linear interpolation; t within its span.
double Interpolate(const std::vector<TimedValue>& series, double t) {
  const auto after = std::upper_bound(series.begin(), series.end(), t,
                                      [](double time, const TimedValue& v) {
                                        return time < v.time_s;
                                      });
  if (after == series.begin()) return series.front().value;
  if (after == series.end()) return series.back().value;
  const TimedValue& a = *(after - 1);
  const TimedValue& b = *after;
  const double w = (t - a.time_s) / (b.time_s - a.time_s);
  return a.value + w * (b.value - a.value);
}

// `series` on the grid origin + i step for i in [first, first + count).
struct Grid {
  long first = 0;
  std::vector<double> values;
};

Grid Resample(const std::vector<TimedValue>& series, double origin, double step) {
  Grid grid;
  grid.first = static_cast<long>(std::ceil((series.front().time_s - origin) / step - 1e-9));
  const long last = static_cast<long>(std::floor((series.back().time_s - origin) / step + 1e-9));
  for (long i = grid.first; i <= last; ++i) {
    grid.values.push_back(Interpolate(series, origin + static_cast<double>(i) * step));
  }
  return grid;
}

// Pearson's r of reference[j] against gyro[j + lag] over their overlap, and
// the overlap's sample count.
double Correlation(const Grid& reference, const Grid& gyro, long lag, long* count) {
  const long begin = std::max(reference.first, gyro.first - lag);
  const long end = std::min(reference.first + static_cast<long>(reference.values.size()),
                            gyro.first + static_cast<long>(gyro.values.size()) - lag);
  *count = std::max(0L, end - begin);
  if (*count < 2) return 0.0;
  double sr = 0, sg = 0, srr = 0, sgg = 0, srg = 0;
  for (long j = begin; j < end; ++j) {
    const double r = reference.values[j - reference.first];
    const double g = gyro.values[j + lag - gyro.first];
    sr += r;
    sg += g;
    srr += r * r;
    sgg += g * g;
    srg += r * g;
  }
  const double n = static_cast<double>(*count);
  const double var_r = srr - sr * sr / n;
  const double var_g = sgg - sg * sg / n;
  if (var_r <= 0 || var_g <= 0) return 0.0;
  return (srg - sr * sg / n) / std::sqrt(var_r * var_g);
}

bool IncreasingAndFinite(const std::vector<TimedValue>& series) {
  for (size_t i = 0; i < series.size(); ++i) {
    if (!std::isfinite(series[i].time_s) || !std::isfinite(series[i].value)) return false;
    if (i > 0 && !(series[i].time_s > series[i - 1].time_s)) return false;
  }
  return true;
}

}  // namespace

Status AlignAngularSpeeds(const std::vector<TimedValue>& gyro_speed,
                          const std::vector<TimedValue>& reference_speed,
                          const AngularSpeedAlignmentOptions& options,
                          AngularSpeedAlignment* alignment) {
  if (!(options.grid_step_s > 0) || !(options.max_time_offset_s > 0)) {
    return Status::Error("angular speed alignment: grid_step_s and max_time_offset_s must be > 0");
  }
  if (gyro_speed.size() < 3 || reference_speed.size() < 3) {
    return Status::Error(fmt::format(
        "angular speed alignment: too few samples ({} gyro, {} reference)", gyro_speed.size(),
        reference_speed.size()));
  }
  if (!IncreasingAndFinite(gyro_speed) || !IncreasingAndFinite(reference_speed)) {
    return Status::Error("angular speed alignment: times not increasing or values not finite");
  }
  const double step = options.grid_step_s;
  const double origin = reference_speed.front().time_s;
  const Grid reference = Resample(reference_speed, origin, step);
  const Grid gyro = Resample(gyro_speed, origin, step);
  const long max_lag = static_cast<long>(std::floor(options.max_time_offset_s / step));
  const long min_count = static_cast<long>(std::ceil(options.min_overlap_s / step));

  std::vector<double> correlation(2 * max_lag + 1, -2.0);  // -2: lag not usable
  long best = 0;
  bool any = false;
  for (long lag = -max_lag; lag <= max_lag; ++lag) {
    long count = 0;
    const double r = Correlation(reference, gyro, lag, &count);
    if (count < std::max(min_count, 3L)) continue;
    correlation[lag + max_lag] = r;
    if (!any || r > correlation[best + max_lag]) best = lag;
    any = true;
  }
  if (!any) {
    return Status::Error(fmt::format(
        "angular speed alignment: the gyro ({:.3f} to {:.3f} s) and the reference ({:.3f} to "
        "{:.3f} s) overlap by less than {} s at every offset within ±{} s",
        gyro_speed.front().time_s, gyro_speed.back().time_s, reference_speed.front().time_s,
        reference_speed.back().time_s, options.min_overlap_s, options.max_time_offset_s));
  }
  const double r_best = correlation[best + max_lag];
  if (r_best == 0.0) {
    return Status::Error("angular speed alignment: no variation of the angular speed to align "
                         "(the sensors did not turn)");
  }
  // Parabola through the best lag and its neighbours: vertex offset in steps.
  double fraction = 0.0;
  if (best > -max_lag && best < max_lag) {
    const double left = correlation[best - 1 + max_lag];
    const double right = correlation[best + 1 + max_lag];
    const double curvature = left - 2 * r_best + right;
    if (left > -2 && right > -2 && curvature < 0) {
      fraction = std::clamp(0.5 * (left - right) / curvature, -0.5, 0.5);
    }
  }
  alignment->time_offset_s = (static_cast<double>(best) + fraction) * step;
  alignment->correlation = r_best;
  alignment->at_search_bound = std::abs(best) >= max_lag - 1;
  // The main peak's lobe: from the best lag down to where r stops falling
  // (a rise of less than 0.001 counts as falling, for noise); the second
  // peak is the best lag outside it.
  const auto usable = [&](long lag) { return correlation[lag + max_lag] > -2; };
  long lobe_begin = best, lobe_end = best;
  while (lobe_begin > -max_lag && usable(lobe_begin - 1) &&
         correlation[lobe_begin - 1 + max_lag] < correlation[lobe_begin + max_lag] + 1e-3) {
    --lobe_begin;
  }
  while (lobe_end < max_lag && usable(lobe_end + 1) &&
         correlation[lobe_end + 1 + max_lag] < correlation[lobe_end + max_lag] + 1e-3) {
    ++lobe_end;
  }
  alignment->second_peak_correlation = -1.0;
  for (long lag = -max_lag; lag <= max_lag; ++lag) {
    if (lag >= lobe_begin && lag <= lobe_end) continue;
    alignment->second_peak_correlation =
        std::max(alignment->second_peak_correlation, correlation[lag + max_lag]);
  }
  // Scale on the original reference samples, the gyro interpolated at t + τ.
  double sum_gr = 0, sum_rr = 0;
  for (const TimedValue& r : reference_speed) {
    const double t = r.time_s + alignment->time_offset_s;
    if (r.value < options.min_reference_speed || t < gyro_speed.front().time_s ||
        t > gyro_speed.back().time_s) {
      continue;
    }
    sum_gr += Interpolate(gyro_speed, t) * r.value;
    sum_rr += r.value * r.value;
  }
  alignment->scale = sum_rr > 0 ? sum_gr / sum_rr : 0.0;
  return Status::Ok();
}

}  // namespace tiltcal::imu
