#include "common/imu/vibration.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::imu {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// Gyro (0..2) and accelerometer (3..5) of one reading.
Vector6d Stack(const ImuReading& r) {
  Vector6d v;
  v << r.angular_velocity_radps, r.linear_acceleration_mps2;
  return v;
}

ImuReading FromStack(double time_s, const Vector6d& v) {
  ImuReading r;
  r.time_s = time_s;
  r.angular_velocity_radps = v.head<3>();
  r.linear_acceleration_mps2 = v.tail<3>();
  return r;
}

// One high-passed grid sample and its index on the grid.
struct HighPassed {
  size_t index;
  Vector6d value;
};

double MedianInterval(const std::vector<ImuReading>& r) {
  std::vector<double> d;
  d.reserve(r.size());
  for (size_t i = 1; i < r.size(); ++i) d.push_back(r[i].time_s - r[i - 1].time_s);
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

}  // namespace

ImuGrid ResampleImu(const std::vector<ImuReading>& r, double max_gap_s) {
  ImuGrid grid;
  if (r.size() < 2) return grid;
  const double dt = MedianInterval(r);
  if (!(dt > 0.0)) return grid;
  grid.start_s = r.front().time_s;
  grid.interval_s = dt;
  const auto n = static_cast<size_t>(std::floor((r.back().time_s - r.front().time_s) / dt)) + 1;
  grid.samples.resize(n);
  size_t j = 0;  // r[j] <= t < r[j + 1]
  for (size_t k = 0; k < n; ++k) {
    const double t = grid.start_s + static_cast<double>(k) * dt;
    while (j + 2 < r.size() && r[j + 1].time_s <= t) ++j;
    const ImuReading& a = r[j];
    const ImuReading& b = r[j + 1];
    const double span = b.time_s - a.time_s;
    if (span > max_gap_s || t < a.time_s || t > b.time_s) continue;
    const double u = (t - a.time_s) / span;
    grid.samples[k] = FromStack(t, (1.0 - u) * Stack(a) + u * Stack(b));
  }
  return grid;
}

ImuGrid LowPassImu(const ImuGrid& grid, double cutoff_hz, double span_s) {
  ImuGrid out = grid;
  std::fill(out.samples.begin(), out.samples.end(), std::nullopt);
  if (!(grid.interval_s > 0.0) || !(cutoff_hz > 0.0) || !(span_s > 0.0)) return out;
  const int half = std::max(1, static_cast<int>(std::floor(0.5 * span_s / grid.interval_s)));
  std::vector<double> taps(static_cast<size_t>(2 * half + 1));
  double sum = 0.0;
  for (int k = -half; k <= half; ++k) {
    const double tau = k * grid.interval_s;
    const double x = 2.0 * cutoff_hz * tau;
    const double sinc = k == 0 ? 1.0 : std::sin(M_PI * x) / (M_PI * x);
    const double u = 2.0 * M_PI * tau / span_s;
    taps[static_cast<size_t>(k + half)] = sinc * (0.42 + 0.5 * std::cos(u) + 0.08 * std::cos(2.0 * u));
    sum += taps[static_cast<size_t>(k + half)];
  }
  for (double& t : taps) t /= sum;
  // missing_before[k]: grid samples without a value among 0 .. k - 1.
  const size_t n = grid.samples.size();
  std::vector<size_t> missing_before(n + 1, 0);
  for (size_t k = 0; k < n; ++k) missing_before[k + 1] = missing_before[k] + (grid.samples[k] ? 0 : 1);
  const auto h = static_cast<size_t>(half);
  for (size_t k = h; k + h < n; ++k) {
    if (missing_before[k + h + 1] != missing_before[k - h]) continue;
    Vector6d low = Vector6d::Zero();
    for (size_t m = 0; m < taps.size(); ++m) low += taps[m] * Stack(*grid.samples[k - h + m]);
    out.samples[k] = FromStack(grid.samples[k]->time_s, low);
  }
  return out;
}

std::vector<ImuReading> LowPassAndDecimateImu(const std::vector<ImuReading>& readings,
                                              const LowPassOptions& options, int step) {
  const ImuGrid low =
      LowPassImu(ResampleImu(readings, options.max_gap_s), options.cutoff_hz, options.span_s);
  std::vector<ImuReading> out;
  const auto s = static_cast<size_t>(std::max(step, 1));
  for (size_t k = 0; k < low.samples.size(); k += s) {
    if (low.samples[k]) out.push_back(*low.samples[k]);
  }
  return out;
}

ImuVibration MeasureImuVibration(const std::vector<ImuReading>& readings,
                                 const VibrationOptions& options) {
  ImuVibration out;
  const ImuGrid grid = ResampleImu(readings, options.low_pass.max_gap_s);
  if (!(grid.interval_s > 0.0)) return out;
  const double dt = grid.interval_s;
  out.sample_rate_hz = 1.0 / dt;
  const ImuGrid low = LowPassImu(grid, options.low_pass.cutoff_hz, options.low_pass.span_s);
  std::vector<HighPassed> hp;
  for (size_t k = 0; k < grid.samples.size(); ++k) {
    if (low.samples[k]) hp.push_back({k, Stack(*grid.samples[k]) - Stack(*low.samples[k])});
  }
  out.num_samples = static_cast<int>(hp.size());
  if (hp.empty()) return out;
  Vector6d sum2 = Vector6d::Zero();
  for (const HighPassed& h : hp) sum2 += h.value.cwiseAbs2();
  const Vector6d rms = (sum2 / static_cast<double>(hp.size())).cwiseSqrt();
  out.gyro.rms = rms.head<3>();
  out.accel.rms = rms.tail<3>();

  // Segments of length consecutive high-passed grid samples.
  const int length = static_cast<int>(std::lround(options.spectrum_segment_s / dt));
  if (length < 8) return out;
  std::vector<size_t> starts;
  for (size_t s = 0; s + static_cast<size_t>(length) <= hp.size();) {
    const size_t e = s + static_cast<size_t>(length) - 1;
    if (hp[e].index - hp[s].index == static_cast<size_t>(length) - 1) {
      starts.push_back(s);
      s += static_cast<size_t>(length);
    } else {
      ++s;
    }
  }
  if (starts.empty()) return out;
  const size_t keep =
      std::min(starts.size(), static_cast<size_t>(std::max(1, options.max_segments)));
  out.num_segments = static_cast<int>(keep);

  // Hann window and the DFT's twiddles, bins 1 .. length / 2.
  const auto n_len = static_cast<size_t>(length);
  std::vector<double> hann(n_len), cosine(n_len), sine(n_len);
  for (size_t n = 0; n < n_len; ++n) {
    const double a = 2.0 * M_PI * static_cast<double>(n) / length;
    hann[n] = 0.5 - 0.5 * std::cos(a);
    cosine[n] = std::cos(a);
    sine[n] = std::sin(a);
  }
  const size_t bins = n_len / 2;
  std::vector<double> gyro_power(bins + 1, 0.0), accel_power(bins + 1, 0.0);
  for (size_t k_seg = 0; k_seg < keep; ++k_seg) {
    const size_t s = starts[k_seg * starts.size() / keep];
    for (size_t k = 1; k <= bins; ++k) {
      Vector6d re = Vector6d::Zero(), im = Vector6d::Zero();
      for (size_t n = 0; n < n_len; ++n) {
        const size_t phase = (k * n) % n_len;
        const Vector6d x = hann[n] * hp[s + n].value;
        re += cosine[phase] * x;
        im -= sine[phase] * x;
      }
      const Vector6d p = re.cwiseAbs2() + im.cwiseAbs2();
      gyro_power[k] += p.head<3>().sum();
      accel_power[k] += p.tail<3>().sum();
    }
  }
  // The strongest bin above the cut-off.
  const double bin_hz = 1.0 / (length * dt);
  const auto first =
      std::max<size_t>(1, static_cast<size_t>(std::ceil(options.low_pass.cutoff_hz / bin_hz)));
  for (auto [power, triad] :
       {std::pair{&gyro_power, &out.gyro}, std::pair{&accel_power, &out.accel}}) {
    if (first > bins) break;
    size_t best = first;
    for (size_t k = first; k <= bins; ++k) {
      if ((*power)[k] > (*power)[best]) best = k;
    }
    triad->peak_frequency_hz = static_cast<double>(best) * bin_hz;
  }
  return out;
}

}  // namespace tiltcal::imu
