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

// The rate and its σ (ppm, LiDAR against IMU) back from a DescribeClockDrift
// sentence ("… runs +249.5 ± 0.3 ppm …", 0.1 ppm resolution); false when the
// sentence does not hold them.
bool ParseClockDriftRate(const std::string& sentence, double* rate_ppm, double* sigma_ppm);

// A time offset that drifts linearly (the calibration's clock model,
// docs/design.md §5): a LiDAR stamp t (s, LiDAR clock, from any fixed origin)
// happened at IMU time t + tau(t) with
//   tau(t) = tau0 + rho (t - t_ref),
// rho = d tau / d t dimensionless. The LiDAR clock's rate against the IMU's
// is dt_l / dt_imu - 1 = 1 / (1 + rho) - 1 = -rho to first order (rho of a
// few hundred ppm: the second order is 1e-7 of it), so a LiDAR clock that
// runs fast (rate > 0) makes tau fall over the sequence.
struct LinearTimeOffset {
  double tau0_s = 0.0;       // tau at reference_s, s
  double rho = 0.0;          // d tau / d t
  double reference_s = 0.0;  // t_ref, s
  // Exactly tau0_s when rho is 0.
  double At(double t_s) const { return rho == 0.0 ? tau0_s : tau0_s + rho * (t_s - reference_s); }
  // The LiDAR clock's rate against the IMU's, ppm (> 0: the LiDAR clock is fast).
  double LidarRatePpm() const { return -rho * 1e6; }
};

// sigma of tau(t) = tau0 + rho dt, dt = t - t_ref, from var(tau0), var(rho)
// and cov(tau0, rho): sqrt(var_tau0 + dt^2 var_rho + 2 dt cov), s (0 when
// the variance is not positive).
double TimeOffsetSigmaAt(double dt_s, double var_tau0_s2, double var_rho, double cov_tau0_rho_s);

// What a user should do about a drifting clock, one sentence, e.g. "the
// LiDAR clock runs +50.0 ppm against the IMU's: tau drifts -8.00 ms over
// 160.0 s (from 4.00 ms at the start to -4.00 ms at the end); synchronise
// the clocks (PTP, GPS PPS), or know that the time offset given here is the
// one at the sequence's middle". rate_ppm: the LiDAR's rate (LidarRatePpm).
std::string DescribeDriftAdvice(double rate_ppm, double span_s, double tau_start_s,
                                double tau_end_s);

}  // namespace tiltcal::timing

#endif  // TILTCAL_COMMON_TIMING_CLOCK_RATE_H_
