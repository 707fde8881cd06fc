#include "stages/calibrate/problem/time_offset_drift.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "common/timing/clock_rate.h"

namespace tiltcal::calibrate {

ScanTimeSpan ScanStampSpan(const std::vector<LidarScan>& scans) {
  ScanTimeSpan span;
  if (scans.empty()) return span;
  const auto [first, last] = std::minmax_element(
      scans.begin(), scans.end(),
      [](const LidarScan& a, const LidarScan& b) { return a.stamp_s < b.stamp_s; });
  span.start_s = first->stamp_s;
  span.end_s = last->stamp_s;
  span.reference_s = 0.5 * (span.start_s + span.end_s);
  return span;
}

namespace {

// rho's prior from decode's rate (use_decode_rate), said in the reason.
void SetDecodePrior(const proto::TimeOffsetDriftParams& params, const std::string& decode_note,
                    TimeOffsetDriftDecision* d) {
  double rate_ppm = 0.0, sigma_ppm = 0.0;
  if (!params.use_decode_rate() ||
      !timing::ParseClockDriftRate(decode_note, &rate_ppm, &sigma_ppm)) {
    return;
  }
  const double prior_sigma_ppm = std::max(sigma_ppm, params.decode_rate_min_sigma_ppm());
  d->prior_rho = -rate_ppm * 1e-6;
  d->prior_sigma = prior_sigma_ppm * 1e-6;
  d->reason +=
      fmt::format("; prior {:+.1f} ± {:.1f} ppm from decode's rate", rate_ppm, prior_sigma_ppm);
}

}  // namespace

TimeOffsetDriftDecision DecideTimeOffsetDrift(const proto::TimeOffsetDriftParams& params,
                                              const std::string& decode_note,
                                              const ScanTimeSpan& span) {
  TimeOffsetDriftDecision d;
  const double expected_drift_s = params.expected_rate_ppm() * 1e-6 * span.length_s();
  switch (params.mode()) {
    case proto::TimeOffsetDriftParams::ON:
      d.estimate = true;
      d.reason = "time_offset_drift.mode ON";
      SetDecodePrior(params, decode_note, &d);
      return d;
    case proto::TimeOffsetDriftParams::OFF:
      d.reason = "time_offset_drift.mode OFF";
      return d;
    default:
      break;
  }
  if (!decode_note.empty()) {
    d.estimate = true;
    d.reason = "AUTO: tiltcal_decode found the clocks drifting";
    SetDecodePrior(params, decode_note, &d);
  } else if (expected_drift_s > params.min_expected_drift_s()) {
    d.estimate = true;
    d.reason = fmt::format(
        "AUTO: {:.1f} ppm (time_offset_drift.expected_rate_ppm) over the scans' {:.1f} s would "
        "move tau by {:.2f} ms, above min_expected_drift_s {:.2f} ms",
        params.expected_rate_ppm(), span.length_s(), expected_drift_s * 1e3,
        params.min_expected_drift_s() * 1e3);
  } else {
    d.reason = fmt::format(
        "AUTO: no drift found by tiltcal_decode, and {:.1f} ppm (expected_rate_ppm) over the "
        "scans' {:.1f} s moves tau by {:.2f} ms only (min_expected_drift_s {:.2f} ms)",
        params.expected_rate_ppm(), span.length_s(), expected_drift_s * 1e3,
        params.min_expected_drift_s() * 1e3);
  }
  return d;
}

ClockRateBounds ClockRateBoundsOfBuild(double rho_bin, double max_rate_ppm,
                                       double time_offset_step_bound_s, double half_length_s) {
  const double highest = max_rate_ppm * 1e-6;
  const double bin = std::clamp(rho_bin, -highest, highest);
  const double step = half_length_s > 0.0 ? time_offset_step_bound_s / half_length_s : highest;
  ClockRateBounds b;
  b.lower = std::max(-highest, bin - step);
  b.upper = std::min(highest, bin + step);
  return b;
}

void FillTimeOffsetDriftReport(const proto::TimeOffsetDriftParams& params,
                               const TimeOffsetDriftDecision& decision, const ScanTimeSpan& span,
                               const TimeOffsetDriftEstimate& estimate,
                               double weak_time_offset_sigma_s,
                               proto::TimeOffsetDriftReport* report) {
  const double tau0_s = estimate.tau0_s;
  const double rho = estimate.rho;
  const ClockRateBounds& bounds = estimate.bounds;
  const std::vector<double>& covariance_row = estimate.covariance_row;
  const double var_tau0_s2 = estimate.var_tau0_s2;
  report->Clear();
  report->set_mode(proto::TimeOffsetDriftParams::Mode_Name(params.mode()));
  report->set_estimated(decision.estimate);
  report->set_reason(decision.reason);
  report->set_reference_time_s(span.reference_s);
  report->set_start_time_s(span.start_s);
  report->set_end_time_s(span.end_s);
  const timing::LinearTimeOffset model{tau0_s, decision.estimate ? rho : 0.0, span.reference_s};
  report->set_time_offset_start_s(model.At(span.start_s));
  report->set_time_offset_end_s(model.At(span.end_s));
  if (!decision.estimate) return;
  report->set_rate_ppm(model.LidarRatePpm());
  if (decision.prior_sigma > 0.0) {
    report->set_rate_prior_ppm(-decision.prior_rho * 1e6);
    report->set_rate_prior_sigma_ppm(decision.prior_sigma * 1e6);
  }
  report->set_rate_lower_bound_ppm(-bounds.upper * 1e6);
  report->set_rate_upper_bound_ppm(-bounds.lower * 1e6);
  if (covariance_row.size() != 8) return;
  for (const double c : covariance_row) report->add_covariance_row(c);
  const double var_rho = std::max(0.0, covariance_row[7]);
  const double cov_tau0_rho = covariance_row[6];
  report->set_rate_sigma_ppm(std::sqrt(var_rho) * 1e6);
  report->set_time_offset_start_sigma_s(timing::TimeOffsetSigmaAt(
      span.start_s - span.reference_s, var_tau0_s2, var_rho, cov_tau0_rho));
  report->set_time_offset_end_sigma_s(
      timing::TimeOffsetSigmaAt(span.end_s - span.reference_s, var_tau0_s2, var_rho, cov_tau0_rho));
  report->set_weak(std::max(report->time_offset_start_sigma_s(),
                            report->time_offset_end_sigma_s()) > weak_time_offset_sigma_s);
}

std::string DescribeTimeOffsetDrift(const proto::TimeOffsetDriftReport& r) {
  if (!r.estimated()) return "";
  return fmt::format(
      "clock drift estimated ({}): the LiDAR clock runs {:+.1f} ± {:.1f} ppm against the IMU's; "
      "tau {:.3f} ± {:.3f} ms at the first scan ({:.1f} s), {:.3f} ± {:.3f} ms at the last "
      "({:.1f} s); time_offset_s is tau at the middle ({:.1f} s)",
      r.reason(), r.rate_ppm(), r.rate_sigma_ppm(), r.time_offset_start_s() * 1e3,
      r.time_offset_start_sigma_s() * 1e3, r.start_time_s(), r.time_offset_end_s() * 1e3,
      r.time_offset_end_sigma_s() * 1e3, r.end_time_s(), r.reference_time_s());
}

}  // namespace tiltcal::calibrate
