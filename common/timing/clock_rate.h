#ifndef TILTCAL_COMMON_TIMING_CLOCK_RATE_H_
#define TILTCAL_COMMON_TIMING_CLOCK_RATE_H_

#include <cstdint>
#include <string>
#include <vector>

namespace tiltcal::timing {

// How fast a sensor's stamp clock runs against the recorder's: the slope of
// d = stamp − record time over the record time. The record times are cut
// into windows of window_s; each window gives the median of its d (the
// transport delay's spread does not move a median much); a least-squares
// line through the windows' (mean record time, median d) gives the slope,
// its σ from the scatter about the line. Two sensors' rates against the
// same recorder give their rate against each other (ClockRateBetween).
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

// The LiDAR clock against the IMU's, from their rates against one recorder.
struct RelativeClockRate {
  bool measured = false;  // both measured, not both stamps_are_record
  double rate_ppm = 0.0;  // lidar − imu: > 0 the LiDAR clock runs fast
  double sigma_ppm = 0.0;
  // |rate| · 1e-6 · overlap_s: how far τ moves over the overlap, s.
  double time_offset_drift_s = 0.0;
};
RelativeClockRate ClockRateBetween(const ClockRate& lidar, const ClockRate& imu, double overlap_s);

// tiltcal_decode's provenance note of imu.binpb that carries the sentence
// below starts with this; tiltcal_calibrate finds it there.
inline const std::string kClockDriftNotePrefix = "clocks: ";

// The sentence the stages print when the drift is significant (above
// max_drift_s and 3 σ), "" otherwise.
std::string DescribeClockDrift(const RelativeClockRate& rate, double overlap_s,
                               double max_drift_s);

}  // namespace tiltcal::timing

#endif  // TILTCAL_COMMON_TIMING_CLOCK_RATE_H_
