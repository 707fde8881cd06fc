#include "stages/inspect/stamp_statistics.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::inspect {

double Quantile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  const double rank = std::clamp(p, 0.0, 1.0) * static_cast<double>(values.size() - 1);
  const auto k = static_cast<size_t>(std::lround(rank));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[k];
}

double Median(std::vector<double> values) { return Quantile(std::move(values), 0.5); }

StampStatistics ComputeStampStatistics(const std::vector<int64_t>& stamps_ns, double gap_factor) {
  StampStatistics s;
  s.gap_factor = gap_factor;
  s.count = static_cast<int64_t>(stamps_ns.size());
  if (stamps_ns.empty()) return s;
  const auto [min_it, max_it] = std::minmax_element(stamps_ns.begin(), stamps_ns.end());
  s.first_ns = *min_it;
  s.last_ns = *max_it;
  std::vector<double> intervals_s;
  intervals_s.reserve(stamps_ns.size());
  for (size_t i = 1; i < stamps_ns.size(); ++i) {
    const int64_t d = stamps_ns[i] - stamps_ns[i - 1];
    if (d == 0) ++s.num_duplicates;
    if (d < 0) ++s.num_backwards;
    if (d > 0) intervals_s.push_back(1e-9 * static_cast<double>(d));
  }
  if (intervals_s.empty()) return s;
  s.nominal_interval_s = Median(intervals_s);
  s.rate_hz = 1.0 / s.nominal_interval_s;
  // Jitter over the intervals that are not gaps (two passes: no cancellation).
  double sum = 0.0;
  int64_t n = 0;
  for (double d : intervals_s) {
    if (d > gap_factor * s.nominal_interval_s) {
      ++s.num_gaps;
      s.longest_gap_s = std::max(s.longest_gap_s, d);
      s.num_missing += std::max<int64_t>(std::llround(d / s.nominal_interval_s) - 1, 1);
    } else {
      sum += d;
      ++n;
    }
  }
  const double mean = sum / static_cast<double>(n);  // n >= 1: the median is no gap
  double sum2 = 0.0;
  for (double d : intervals_s) {
    if (d <= gap_factor * s.nominal_interval_s) sum2 += (d - mean) * (d - mean);
  }
  s.interval_stddev_s = std::sqrt(sum2 / static_cast<double>(n));
  return s;
}

}  // namespace tiltcal::inspect
