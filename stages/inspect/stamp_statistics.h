#ifndef TILTCAL_STAGES_INSPECT_STAMP_STATISTICS_H_
#define TILTCAL_STAGES_INSPECT_STAMP_STATISTICS_H_

#include <cstdint>
#include <vector>

namespace tiltcal::inspect {

// What the header stamps of one topic say about its timing, in message
// (record) order. The nominal interval is the median of the positive
// intervals; the rate is its inverse.
struct StampStatistics {
  double gap_factor = 0.0;  // the definition of a gap used
  int64_t count = 0;
  int64_t first_ns = 0;  // smallest stamp
  int64_t last_ns = 0;   // largest stamp
  double nominal_interval_s = 0.0;
  double rate_hz = 0.0;            // 1 / nominal_interval_s (0 with < 2 stamps)
  double interval_stddev_s = 0.0;  // jitter: σ of the positive intervals that are no gap
  int64_t num_gaps = 0;            // intervals > gap_factor · nominal
  double longest_gap_s = 0.0;      // longest such interval (0 without gaps)
  // Messages missing in the gaps: sum over gaps of round(interval / nominal) - 1.
  int64_t num_missing = 0;
  int64_t num_duplicates = 0;      // interval == 0
  int64_t num_backwards = 0;       // interval < 0
  double span_s() const { return 1e-9 * static_cast<double>(last_ns - first_ns); }
};

StampStatistics ComputeStampStatistics(const std::vector<int64_t>& stamps_ns, double gap_factor);

// Median of `values` (0 when empty); takes a copy.
double Median(std::vector<double> values);
// The p-quantile (p in [0, 1], nearest rank) of `values` (0 when empty).
double Quantile(std::vector<double> values, double p);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_STAMP_STATISTICS_H_
