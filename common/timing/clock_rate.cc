#include "common/timing/clock_rate.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numeric>

#include <fmt/format.h>

namespace tiltcal::timing {
namespace {

double Median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

}  // namespace

ClockRate EstimateClockRate(const std::vector<int64_t>& stamps_ns,
                            const std::vector<int64_t>& record_ns, double window_s) {
  ClockRate out;
  const size_t n = std::min(stamps_ns.size(), record_ns.size());
  if (n < 3 || !(window_s > 0.0)) return out;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return record_ns[a] < record_ns[b]; });
  out.stamps_are_record = std::all_of(order.begin(), order.end(),
                                      [&](size_t i) { return stamps_ns[i] == record_ns[i]; });
  const int64_t origin_ns = record_ns[order.front()];
  const int64_t offset_ns = stamps_ns[order.front()] - origin_ns;
  // (mean record time, median d) per window, s from the first record.
  std::vector<double> t, d;
  std::vector<double> window_d;
  double window_t = 0.0;
  int64_t window_index = -1;
  auto close = [&] {
    if (window_d.empty()) return;
    t.push_back(window_t / static_cast<double>(window_d.size()));
    d.push_back(Median(window_d));
    window_d.clear();
    window_t = 0.0;
  };
  for (size_t i : order) {
    const double record_s = 1e-9 * static_cast<double>(record_ns[i] - origin_ns);
    const auto w = static_cast<int64_t>(std::floor(record_s / window_s));
    if (w != window_index) {
      close();
      window_index = w;
    }
    window_t += record_s;
    window_d.push_back(1e-9 * static_cast<double>(stamps_ns[i] - record_ns[i] - offset_ns));
  }
  close();
  out.windows = static_cast<int>(t.size());
  if (t.size() < 3) return out;
  const double mean_t = std::accumulate(t.begin(), t.end(), 0.0) / static_cast<double>(t.size());
  const double mean_d = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(d.size());
  double stt = 0.0, std_ = 0.0;
  for (size_t k = 0; k < t.size(); ++k) {
    stt += (t[k] - mean_t) * (t[k] - mean_t);
    std_ += (t[k] - mean_t) * (d[k] - mean_d);
  }
  if (!(stt > 0.0)) return out;
  const double slope = std_ / stt;
  double scatter = 0.0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double r = d[k] - mean_d - slope * (t[k] - mean_t);
    scatter += r * r;
  }
  out.measured = true;
  out.rate_ppm = 1e6 * slope;
  out.sigma_ppm = 1e6 * std::sqrt(scatter / static_cast<double>(t.size() - 2) / stt);
  return out;
}

RelativeClockRate ClockRateBetween(const ClockRate& lidar, const ClockRate& imu, double overlap_s) {
  RelativeClockRate out;
  out.measured = lidar.measured && imu.measured && !(lidar.stamps_are_record && imu.stamps_are_record);
  if (!out.measured) return out;
  out.rate_ppm = lidar.rate_ppm - imu.rate_ppm;
  out.sigma_ppm = std::hypot(lidar.sigma_ppm, imu.sigma_ppm);
  out.time_offset_drift_s = std::abs(out.rate_ppm) * 1e-6 * std::max(overlap_s, 0.0);
  return out;
}

std::string DescribeClockDrift(const RelativeClockRate& rate, double overlap_s,
                               double max_drift_s) {
  if (!rate.measured || rate.time_offset_drift_s <= max_drift_s ||
      std::abs(rate.rate_ppm) <= 3.0 * rate.sigma_ppm) {
    return "";
  }
  return fmt::format(
      "the LiDAR clock runs {:+.1f} ± {:.1f} ppm against the IMU's (their stamps against the "
      "record times): τ drifts by {:.2f} ms over the {:.1f} s of overlap, so one τ for the "
      "whole sequence has its ends off by about half that (tiltcal_calibrate estimates the rate: "
      "time_offset_drift); τ stays within {:.1f} ms only over {:.0f} s: synchronise the clocks "
      "(PTP, GPS PPS) or calibrate shorter recordings",
      rate.rate_ppm, rate.sigma_ppm, 1e3 * rate.time_offset_drift_s, overlap_s, 1e3 * max_drift_s,
      max_drift_s / (std::abs(rate.rate_ppm) * 1e-6));
}

bool ParseClockDriftRate(const std::string& sentence, double* rate_ppm, double* sigma_ppm) {
  const std::string runs = "runs ";
  const std::string plus_minus = " ± ";
  const size_t at = sentence.find(runs);
  if (at == std::string::npos) return false;
  const char* begin = sentence.c_str() + at + runs.size();
  char* end = nullptr;
  const double rate = std::strtod(begin, &end);
  if (end == begin || sentence.compare(static_cast<size_t>(end - sentence.c_str()),
                                       plus_minus.size(), plus_minus) != 0) {
    return false;
  }
  begin = end + plus_minus.size();
  const double sigma = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(rate) || !std::isfinite(sigma) || sigma < 0.0) return false;
  *rate_ppm = rate;
  *sigma_ppm = sigma;
  return true;
}

double TimeOffsetSigmaAt(double dt_s, double var_tau0_s2, double var_rho, double cov_tau0_rho_s) {
  const double variance = var_tau0_s2 + dt_s * dt_s * var_rho + 2.0 * dt_s * cov_tau0_rho_s;
  return variance > 0.0 ? std::sqrt(variance) : 0.0;
}

std::string DescribeDriftAdvice(double rate_ppm, double span_s, double tau_start_s,
                                double tau_end_s) {
  return fmt::format(
      "the LiDAR clock runs {:+.1f} ppm against the IMU's: tau drifts {:+.2f} ms over {:.1f} s "
      "(from {:.2f} ms at the start to {:.2f} ms at the end); synchronise the clocks (PTP, GPS "
      "PPS), or know that the time offset given here is the one at the sequence's middle and "
      "is off by up to {:.2f} ms at its ends",
      rate_ppm, 1e3 * (tau_end_s - tau_start_s), span_s, 1e3 * tau_start_s, 1e3 * tau_end_s,
      0.5e3 * std::abs(tau_end_s - tau_start_s));
}

}  // namespace tiltcal::timing
