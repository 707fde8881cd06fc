#ifndef TILTCAL_STAGES_CALIBRATE_PROBLEM_TIME_OFFSET_DRIFT_H_
#define TILTCAL_STAGES_CALIBRATE_PROBLEM_TIME_OFFSET_DRIFT_H_

// A linear clock drift of the time offset in the calibration (docs/design.md
// §5; params CalibrateParams.time_offset_drift):
//   a LiDAR stamp t happened at IMU time t + tau(t),
//   tau(t) = tau0 + rho (t - t_ref)
// t: LiDAR clock, s from the first IMU stamp (the calibrator's times);
// t_ref: the middle of the scans' stamps, (t_first + t_last) / 2, where tau0
// and rho are uncorrelated for evenly spread residuals; tau0: the state's
// time_offset_s, the result's time_offset_s (the sequence's best single
// offset, as without the drift); rho: the state's clock_rate, d tau / d t,
// dimensionless (the LiDAR clock's rate against the IMU's is -rho:
// common/timing/clock_rate.h).
//
// rho enters every residual that uses tau through
// DriftingTimeOffsetCostFunction (LiDAR point-to-plane, flat and inclination
// ground residuals) and every map / deskew / association through
// CalibrationState::TimeOffsetAt. Without the drift rho stays 0, its block is
// not in the problem, and the single-tau path is the one before it.
//
// Bounds of one build (problem_builder.h), as tau's: |rho| <= max_rate_ppm,
// and rho moves at most S / max|t - t_ref| from the value that chose the
// frozen knot windows (S = outer_loop.time_offset_step_bound_s): no residual's
// tau moves more than 2 S from its binning value. With decode's measured
// rate (use_decode_rate), rho starts there and has a prior N(that, sigma^2),
// sigma = max(decode's, decode_rate_min_sigma_ppm) (ScalarPriorCost in
// problem_builder.cc); otherwise rho starts at 0 without a prior.

#include <string>
#include <vector>

#include "stages/calibrate/problem/lidar_scans.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// The scans' stamps: first, last and t_ref (LiDAR clock, s from the first IMU
// stamp); all 0 without scans.
struct ScanTimeSpan {
  double start_s = 0.0;
  double end_s = 0.0;
  double reference_s = 0.0;
  double length_s() const { return end_s - start_s; }
  // max |t - t_ref| over the scans, s.
  double half_length_s() const { return 0.5 * (end_s - start_s); }
};
ScanTimeSpan ScanStampSpan(const std::vector<LidarScan>& scans);

// Whether rho is estimated, and why (the report's reason):
//   ON: always; OFF: never;
//   AUTO: when decode_note (tiltcal_decode's clock-drift note, "" without) is
//   not empty, or when expected_rate_ppm * 1e-6 * span length exceeds
//   min_expected_drift_s.
// With use_decode_rate and a rate in the note: rho's prior (and start) at
// -rate * 1e-6 with sigma max(decode's sigma, decode_rate_min_sigma_ppm) * 1e-6.
struct TimeOffsetDriftDecision {
  bool estimate = false;
  std::string reason;
  double prior_rho = 0.0;
  double prior_sigma = 0.0;  // 0: no prior
};
TimeOffsetDriftDecision DecideTimeOffsetDrift(const proto::TimeOffsetDriftParams& params,
                                              const std::string& decode_note,
                                              const ScanTimeSpan& span);

// rho's interval in one build (above): [lower, upper], dimensionless.
struct ClockRateBounds {
  double lower = 0.0;
  double upper = 0.0;
};
ClockRateBounds ClockRateBoundsOfBuild(double rho_bin, double max_rate_ppm,
                                       double time_offset_step_bound_s, double half_length_s);

// The estimate a drift report is made from: tau0 (the state's) and rho, rho's
// interval, covariance_row: cov(rho, .) with the 7 tangent parameters of the
// result's covariance (tau0 last), then var(rho) (8 values; empty: no
// covariance), and var(tau0), s^2.
struct TimeOffsetDriftEstimate {
  double tau0_s = 0.0;
  double rho = 0.0;
  ClockRateBounds bounds;
  std::vector<double> covariance_row;
  double var_tau0_s2 = 0.0;
};

// Fills *report (mode, decision, span) and, when estimated, the rate and tau
// at both ends with their sigmas from the estimate's covariance row (without
// one the sigmas stay 0). weak: tau at the first or the last scan has a
// sigma above weak_time_offset_sigma_s (tau is then not determined at every
// time of the sequence, as a single tau with such a sigma is weak).
void FillTimeOffsetDriftReport(const proto::TimeOffsetDriftParams& params,
                               const TimeOffsetDriftDecision& decision, const ScanTimeSpan& span,
                               const TimeOffsetDriftEstimate& estimate,
                               double weak_time_offset_sigma_s,
                               proto::TimeOffsetDriftReport* report);

// The verdict note of an estimated drift (the rate and tau at both ends with
// their sigmas), "" when not estimated.
std::string DescribeTimeOffsetDrift(const proto::TimeOffsetDriftReport& report);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_PROBLEM_TIME_OFFSET_DRIFT_H_
