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

// r(lag) for lag in [-max_lag, max_lag] (index lag + max_lag); kUnusable
// where the overlap is shorter than min_count grid samples.
constexpr double kUnusable = -2.0;

struct CorrelationCurve {
  long max_lag = 0;
  std::vector<double> r;
  double at(long lag) const { return r[lag + max_lag]; }
  bool usable(long lag) const { return at(lag) > kUnusable; }
};

CorrelationCurve CorrelateOverLags(const Grid& reference, const Grid& gyro, long max_lag,
                                   long min_count) {
  CorrelationCurve curve{max_lag, std::vector<double>(2 * max_lag + 1, kUnusable)};
  for (long lag = -max_lag; lag <= max_lag; ++lag) {
    long count = 0;
    const double r = Correlation(reference, gyro, lag, &count);
    if (count >= std::max(min_count, 3L)) curve.r[lag + max_lag] = r;
  }
  return curve;
}

// Offset of the parabola's vertex through the best lag and its neighbours,
// in grid steps within [-0.5, 0.5].
double PeakFraction(const CorrelationCurve& curve, long best) {
  if (best <= -curve.max_lag || best >= curve.max_lag) return 0.0;
  if (!curve.usable(best - 1) || !curve.usable(best + 1)) return 0.0;
  const double left = curve.at(best - 1), right = curve.at(best + 1);
  const double curvature = left - 2 * curve.at(best) + right;
  return curvature < 0 ? std::clamp(0.5 * (left - right) / curvature, -0.5, 0.5) : 0.0;
}

// The best r outside the main peak's lobe: the lags around `best` over which
// r keeps falling (a rise of less than 0.001 counts as falling, for noise).
double SecondPeak(const CorrelationCurve& curve, long best) {
  const long max_lag = curve.max_lag;
  long begin = best, end = best;
  while (begin > -max_lag && curve.usable(begin - 1) &&
         curve.at(begin - 1) < curve.at(begin) + 1e-3) {
    --begin;
  }
  while (end < max_lag && curve.usable(end + 1) && curve.at(end + 1) < curve.at(end) + 1e-3) {
    ++end;
  }
  double second = -1.0;
  for (long lag = -max_lag; lag <= max_lag; ++lag) {
    if (lag < begin || lag > end) second = std::max(second, curve.at(lag));
  }
  return second;
}

// Σ s_g(t + τ) s_r(t) / Σ s_r(t)² over the reference samples faster than
// min_speed whose t + τ is within the gyro's span.
double Scale(const std::vector<TimedValue>& gyro_speed,
             const std::vector<TimedValue>& reference_speed, double time_offset_s,
             double min_speed) {
  double sum_gr = 0, sum_rr = 0;
  for (const TimedValue& r : reference_speed) {
    const double t = r.time_s + time_offset_s;
    if (r.value < min_speed || t < gyro_speed.front().time_s || t > gyro_speed.back().time_s) {
      continue;
    }
    sum_gr += Interpolate(gyro_speed, t) * r.value;
    sum_rr += r.value * r.value;
  }
  return sum_rr > 0 ? sum_gr / sum_rr : 0.0;
}

Status CheckInputs(const std::vector<TimedValue>& gyro_speed,
                   const std::vector<TimedValue>& reference_speed,
                   const AngularSpeedAlignmentOptions& options) {
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
  return Status::Ok();
}

}  // namespace

Status AlignAngularSpeeds(const std::vector<TimedValue>& gyro_speed,
                          const std::vector<TimedValue>& reference_speed,
                          const AngularSpeedAlignmentOptions& options,
                          AngularSpeedAlignment* alignment) {
  TILTCAL_RETURN_IF_ERROR(CheckInputs(gyro_speed, reference_speed, options));
  const double step = options.grid_step_s;
  const double origin = reference_speed.front().time_s;
  const long max_lag = static_cast<long>(std::floor(options.max_time_offset_s / step));
  const CorrelationCurve curve =
      CorrelateOverLags(Resample(reference_speed, origin, step), Resample(gyro_speed, origin, step),
                        max_lag, static_cast<long>(std::ceil(options.min_overlap_s / step)));
  long best = 0;
  bool any = false;
  for (long lag = -max_lag; lag <= max_lag; ++lag) {
    if (curve.usable(lag) && (!any || curve.at(lag) > curve.at(best))) best = lag;
    any = any || curve.usable(lag);
  }
  if (!any) {
    return Status::Error(fmt::format(
        "angular speed alignment: the gyro ({:.3f} to {:.3f} s) and the reference ({:.3f} to "
        "{:.3f} s) overlap by less than {} s at every offset within ±{} s",
        gyro_speed.front().time_s, gyro_speed.back().time_s, reference_speed.front().time_s,
        reference_speed.back().time_s, options.min_overlap_s, options.max_time_offset_s));
  }
  if (curve.at(best) == 0.0) {
    return Status::Error("angular speed alignment: no variation of the angular speed to align "
                         "(the sensors did not turn)");
  }
  alignment->time_offset_s = (static_cast<double>(best) + PeakFraction(curve, best)) * step;
  alignment->correlation = curve.at(best);
  alignment->at_search_bound = std::abs(best) >= max_lag - 1;
  alignment->second_peak_correlation = SecondPeak(curve, best);
  alignment->scale = Scale(gyro_speed, reference_speed, alignment->time_offset_s,
                           options.min_reference_speed);
  return Status::Ok();
}

}  // namespace tiltcal::imu
