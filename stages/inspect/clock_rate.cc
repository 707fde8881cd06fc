#include "stages/inspect/clock_rate.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "stages/inspect/stamp_statistics.h"

namespace tiltcal::inspect {

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

}  // namespace tiltcal::inspect
