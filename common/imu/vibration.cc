#include "common/imu/vibration.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::imu {
namespace {

// A sample interval longer than this many median intervals is a gap.
constexpr double kGapFactor = 1.5;

using Vector6d = Eigen::Matrix<double, 6, 1>;

double MedianInterval(const std::vector<ImuReading>& r) {
  std::vector<double> d;
  d.reserve(r.size());
  for (size_t i = 1; i < r.size(); ++i) d.push_back(r[i].time_s - r[i - 1].time_s);
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

// Gyro (0..2) and accelerometer (3..5) of one reading.
Vector6d Stack(const ImuReading& r) {
  Vector6d v;
  v << r.angular_velocity_radps, r.linear_acceleration_mps2;
  return v;
}

// One high-passed sample and its index in the readings.
struct HighPassed {
  size_t index;
  Vector6d value;
};

// The low-pass: a windowed sinc of cut-off fc over ±half samples,
//   h_k = 2 fc dt sinc(2 fc k dt) w_k,  w_k Blackman over the span,
// normalised to sum 1 (unit gain at 0 Hz).
std::vector<double> LowPassKernel(double cutoff_hz, double dt, int half) {
  std::vector<double> h(static_cast<size_t>(2 * half + 1));
  double sum = 0.0;
  for (int k = -half; k <= half; ++k) {
    const double x = 2.0 * cutoff_hz * dt * k;
    const double sinc = k == 0 ? 1.0 : std::sin(M_PI * x) / (M_PI * x);
    const double u = static_cast<double>(k + half) / (2.0 * half);
    const double blackman = 0.42 - 0.5 * std::cos(2.0 * M_PI * u) + 0.08 * std::cos(4.0 * M_PI * u);
    h[static_cast<size_t>(k + half)] = sinc * blackman;
    sum += sinc * blackman;
  }
  for (double& v : h) v /= sum;
  return h;
}

// Each reading minus its low-pass, where the readings i - half .. i + half
// exist and hold no gap (an interval above max_interval_s).
std::vector<HighPassed> HighPass(const std::vector<ImuReading>& r, const VibrationOptions& o,
                                 double dt) {
  const int half = std::max(1, static_cast<int>(std::lround(0.5 * o.filter_span_s / dt)));
  const std::vector<double> h = LowPassKernel(o.cutoff_hz, dt, half);
  // gaps_before[i]: gaps among the intervals ending at readings 1 .. i.
  std::vector<int> gaps_before(r.size(), 0);
  for (size_t i = 1; i < r.size(); ++i) {
    gaps_before[i] = gaps_before[i - 1] + (r[i].time_s - r[i - 1].time_s > kGapFactor * dt ? 1 : 0);
  }
  std::vector<HighPassed> out;
  const auto n = static_cast<long>(r.size());
  for (long i = half; i + half < n; ++i) {
    if (gaps_before[static_cast<size_t>(i + half)] != gaps_before[static_cast<size_t>(i - half)]) continue;
    Vector6d low = Vector6d::Zero();
    for (int k = -half; k <= half; ++k) {
      low += h[static_cast<size_t>(k + half)] * Stack(r[static_cast<size_t>(i + k)]);
    }
    out.push_back({static_cast<size_t>(i), Stack(r[static_cast<size_t>(i)]) - low});
  }
  return out;
}

}  // namespace

ImuVibration MeasureImuVibration(const std::vector<ImuReading>& readings,
                                 const VibrationOptions& options) {
  ImuVibration out;
  if (readings.size() < 8 || !(options.cutoff_hz > 0.0) || !(options.filter_span_s > 0.0)) {
    return out;
  }
  const double dt = MedianInterval(readings);
  if (!(dt > 0.0)) return out;
  out.sample_rate_hz = 1.0 / dt;
  const std::vector<HighPassed> hp = HighPass(readings, options, dt);
  out.num_samples = static_cast<int>(hp.size());
  if (hp.empty()) return out;
  Vector6d sum2 = Vector6d::Zero();
  for (const HighPassed& h : hp) sum2 += h.value.cwiseAbs2();
  const Vector6d rms = (sum2 / static_cast<double>(hp.size())).cwiseSqrt();
  out.gyro.rms = rms.head<3>();
  out.accel.rms = rms.tail<3>();

  // Segments of consecutive high-passed samples (consecutive readings, no gap).
  const int length = static_cast<int>(std::lround(options.spectrum_segment_s / dt));
  if (length < 8) return out;
  std::vector<size_t> starts;
  for (size_t s = 0; s + static_cast<size_t>(length) <= hp.size();) {
    const size_t e = s + static_cast<size_t>(length) - 1;
    if (hp[e].index - hp[s].index == static_cast<size_t>(length) - 1 &&
        readings[hp[e].index].time_s - readings[hp[s].index].time_s <=
            kGapFactor * dt * (length - 1)) {
      starts.push_back(s);
      s += static_cast<size_t>(length);
    } else {
      ++s;
    }
  }
  if (starts.empty()) return out;
  const size_t keep = std::min(starts.size(), static_cast<size_t>(std::max(1, options.max_segments)));
  std::vector<size_t> chosen;
  for (size_t k = 0; k < keep; ++k) chosen.push_back(starts[k * starts.size() / keep]);
  out.num_segments = static_cast<int>(chosen.size());

  // Hann window and the DFT's twiddles, bins 1 .. length / 2.
  std::vector<double> hann(static_cast<size_t>(length)), cosine(static_cast<size_t>(length)),
      sine(static_cast<size_t>(length));
  for (int n = 0; n < length; ++n) {
    hann[static_cast<size_t>(n)] = 0.5 - 0.5 * std::cos(2.0 * M_PI * n / length);
    cosine[static_cast<size_t>(n)] = std::cos(2.0 * M_PI * n / length);
    sine[static_cast<size_t>(n)] = std::sin(2.0 * M_PI * n / length);
  }
  const int bins = length / 2;
  std::vector<double> gyro_power(static_cast<size_t>(bins) + 1, 0.0),
      accel_power(static_cast<size_t>(bins) + 1, 0.0);
  for (size_t s : chosen) {
    for (int k = 1; k <= bins; ++k) {
      Vector6d re = Vector6d::Zero();
      Vector6d im = Vector6d::Zero();
      for (int n = 0; n < length; ++n) {
        const auto phase = static_cast<size_t>((static_cast<long>(k) * n) % length);
        const Vector6d x = hann[static_cast<size_t>(n)] * hp[s + static_cast<size_t>(n)].value;
        re += cosine[phase] * x;
        im -= sine[phase] * x;
      }
      const Vector6d p = re.cwiseAbs2() + im.cwiseAbs2();
      gyro_power[static_cast<size_t>(k)] += p.head<3>().sum();
      accel_power[static_cast<size_t>(k)] += p.tail<3>().sum();
    }
  }
  // The strongest bin above the cut-off.
  const double bin_hz = 1.0 / (length * dt);
  const int first = std::max(1, static_cast<int>(std::ceil(options.cutoff_hz / bin_hz)));
  for (auto [power, triad] : {std::pair{&gyro_power, &out.gyro}, std::pair{&accel_power, &out.accel}}) {
    int best = first;
    for (int k = first; k <= bins; ++k) {
      if ((*power)[static_cast<size_t>(k)] > (*power)[static_cast<size_t>(best)]) best = k;
    }
    triad->peak_frequency_hz = best <= bins ? best * bin_hz : 0.0;
  }
  return out;
}

}  // namespace tiltcal::imu
