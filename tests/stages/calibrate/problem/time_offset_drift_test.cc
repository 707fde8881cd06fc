// The clock drift's decisions and numbers (stages/calibrate/problem/time_offset_drift.h):
// when AUTO estimates the rate, the bounds of one build, tau at the ends with
// their sigma, and the single-tau path staying exactly tau0.

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "common/timing/clock_rate.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/time_offset_drift.h"
#include "tests/stages/calibrate/calibrate_params_text.h"

namespace tiltcal::calibrate {
namespace {

proto::TimeOffsetDriftParams DriftParams(const char* mode = "AUTO") {
  return tiltcal::testing::DefaultCalibrateParamsWith(std::string("time_offset_drift { mode: ") +
                                                      mode + " }")
      .time_offset_drift();
}

ScanTimeSpan DriftSpan(double start_s, double end_s) {
  ScanTimeSpan span;
  span.start_s = start_s;
  span.end_s = end_s;
  span.reference_s = 0.5 * (start_s + end_s);
  return span;
}

TEST(TimeOffsetDriftTest, AutoEstimatesOnDecodesNoteOrALongSequence) {
  // 5 ppm over 60 s is 0.3 ms: not estimated; over 160 s 0.8 ms: estimated.
  EXPECT_FALSE(DecideTimeOffsetDrift(DriftParams(), "", DriftSpan(1.0, 61.0)).estimate);
  const TimeOffsetDriftDecision longer =
      DecideTimeOffsetDrift(DriftParams(), "", DriftSpan(1.0, 161.0));
  EXPECT_TRUE(longer.estimate);
  EXPECT_NE(longer.reason.find("0.80 ms"), std::string::npos) << longer.reason;
  EXPECT_TRUE(
      DecideTimeOffsetDrift(DriftParams(), "the LiDAR clock runs", DriftSpan(1.0, 17.0)).estimate);
  EXPECT_FALSE(
      DecideTimeOffsetDrift(DriftParams("OFF"), "the LiDAR clock runs", DriftSpan(1.0, 161.0))
          .estimate);
  EXPECT_TRUE(DecideTimeOffsetDrift(DriftParams("ON"), "", DriftSpan(1.0, 5.0)).estimate);
}

// decode's rate (its note's "runs +249.5 ± 0.3 ppm") becomes rho's prior,
// with its sigma floored; without use_decode_rate, or a note without the
// rate, there is none.
TEST(TimeOffsetDriftTest, DecodesRateIsThePrior) {
  const std::string note =
      "the LiDAR clock runs +249.5 ± 0.3 ppm against the IMU's (their stamps against the record "
      "times): τ drifts by 3.94 ms";
  double rate = 0.0, sigma = 0.0;
  ASSERT_TRUE(timing::ParseClockDriftRate(note, &rate, &sigma));
  EXPECT_DOUBLE_EQ(rate, 249.5);
  EXPECT_DOUBLE_EQ(sigma, 0.3);
  EXPECT_FALSE(timing::ParseClockDriftRate("the LiDAR clock runs fast", &rate, &sigma));
  const TimeOffsetDriftDecision d = DecideTimeOffsetDrift(DriftParams(), note, DriftSpan(0, 20));
  EXPECT_TRUE(d.estimate);
  EXPECT_DOUBLE_EQ(d.prior_rho, -249.5e-6);
  EXPECT_DOUBLE_EQ(d.prior_sigma, 2e-6);  // decode_rate_min_sigma_ppm
  proto::TimeOffsetDriftParams without = DriftParams();
  without.set_use_decode_rate(false);
  EXPECT_EQ(DecideTimeOffsetDrift(without, note, DriftSpan(0, 20)).prior_sigma, 0.0);
  EXPECT_EQ(DecideTimeOffsetDrift(DriftParams(), "clocks drift", DriftSpan(0, 20)).prior_sigma,
            0.0);
}

TEST(TimeOffsetDriftTest, RateBoundsOfABuild) {
  // S = 15 ms over H = 80 s: 187.5 ppm per build, within +-2000 ppm.
  ClockRateBounds b = ClockRateBoundsOfBuild(1e-4, 2000.0, 0.015, 80.0);
  EXPECT_NEAR(b.lower, 1e-4 - 187.5e-6, 1e-12);
  EXPECT_NEAR(b.upper, 1e-4 + 187.5e-6, 1e-12);
  b = ClockRateBoundsOfBuild(1.9e-3, 2000.0, 0.015, 80.0);
  EXPECT_DOUBLE_EQ(b.upper, 2e-3);
}

// tau at the ends: tau0 + rho dt, sigma^2 = var tau0 + dt^2 var rho + 2 dt cov.
TEST(TimeOffsetDriftTest, EndsAndTheirSigmas) {
  const ScanTimeSpan span = DriftSpan(2.0, 162.0);  // t_ref 82, dt -80 and +80
  TimeOffsetDriftDecision decision{true, "ON"};
  std::vector<double> row(8, 0.0);
  row[6] = 2e-12;                // cov(tau0, rho), s
  row[7] = 1e-14;                // var rho (0.1 ppm)
  const double var_tau0 = 1e-8;  // (0.1 ms)^2
  TimeOffsetDriftEstimate estimate{0.012, -50e-6, {-1e-3, 1e-3}, row, var_tau0};
  proto::TimeOffsetDriftReport r;
  FillTimeOffsetDriftReport(DriftParams(), decision, span, estimate, 5e-4, &r);
  EXPECT_TRUE(r.estimated());
  EXPECT_DOUBLE_EQ(r.rate_ppm(), 50.0);
  EXPECT_NEAR(r.rate_sigma_ppm(), 0.1, 1e-9);
  EXPECT_NEAR(r.time_offset_start_s(), 0.012 + 50e-6 * 80.0, 1e-15);
  EXPECT_NEAR(r.time_offset_end_s(), 0.012 - 50e-6 * 80.0, 1e-15);
  EXPECT_NEAR(r.time_offset_start_sigma_s(),
              std::sqrt(var_tau0 + 6400.0 * 1e-14 - 2.0 * 80.0 * 2e-12), 1e-15);
  EXPECT_NEAR(r.time_offset_end_sigma_s(),
              std::sqrt(var_tau0 + 6400.0 * 1e-14 + 2.0 * 80.0 * 2e-12), 1e-15);
  EXPECT_FALSE(r.weak());  // 0.1 ppm over 160 s: 16 us
  estimate.covariance_row[7] = 4e-11;  // 6.3 ppm: tau at the ends known to 0.52 ms
  FillTimeOffsetDriftReport(DriftParams(), decision, span, estimate, 5e-4, &r);
  EXPECT_TRUE(r.weak());
  EXPECT_NE(DescribeTimeOffsetDrift(r).find("+50.0 ± 6.3 ppm"), std::string::npos)
      << DescribeTimeOffsetDrift(r);
}

// Without the drift (rho 0) every tau is tau0 itself, whatever t.
TEST(TimeOffsetDriftTest, WithoutARateTauIsTau0Exactly) {
  CalibrationState state(spline::UniformKnotGrid::ForDuration(0.0, 10.0, 0.05));
  state.time_offset_s[0] = 0.0123456789;
  state.time_reference_s = 5.0;
  for (double t : {0.0, 1.7, 5.0, 9.3}) EXPECT_EQ(state.TimeOffsetAt(t), state.time_offset_s[0]);
  state.clock_rate[0] = 1e-4;
  EXPECT_DOUBLE_EQ(state.TimeOffsetAt(9.0), 0.0123456789 + 4e-4);
}

}  // namespace
}  // namespace tiltcal::calibrate
