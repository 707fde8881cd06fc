#ifndef TILTCAL_STAGES_INSPECT_CLOCK_RATE_H_
#define TILTCAL_STAGES_INSPECT_CLOCK_RATE_H_

#include <cstdint>
#include <vector>

namespace tiltcal::inspect {

// How fast a sensor's stamp clock runs against the recorder's: the slope of
// d = stamp − record time over the record time. The record times are cut
// into windows of window_s; each window gives the median of its d (the
// transport delay's spread does not move a median much); a least-squares
// line through the windows' (mean record time, median d) gives the slope,
// its σ from the scatter about the line. Two sensors' rates against the
// same recorder give their rate against each other.
struct ClockRate {
  bool measured = false;     // at least 3 windows with messages
  bool stamps_are_record = false;  // every stamp equals its record time
  double rate_ppm = 0.0;     // (d slope) · 1e6: > 0 the stamp clock runs fast
  double sigma_ppm = 0.0;
  int windows = 0;
};

// stamps_ns[i] and record_ns[i] of one message each, in any order.
ClockRate EstimateClockRate(const std::vector<int64_t>& stamps_ns,
                            const std::vector<int64_t>& record_ns, double window_s);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_CLOCK_RATE_H_
