// The verdict rules (stages/calibrate/report/verdict.h), each on a hand-made
// result: a clean result is OK, and each fault alone turns it SUSPECT (or
// WEAK) with a reason that says what is wrong.

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "stages/calibrate/report/residual_statistics.h"
#include "stages/calibrate/report/verdict.h"
#include "tests/stages/calibrate/calibrate_params_text.h"

namespace tiltcal::calibrate {
namespace {

using proto::CalibrationResult;

proto::VerdictParams Params() { return tiltcal::testing::DefaultCalibrateParamsWith().verdict(); }

void SetRigid(double qw, double qz, double x, double y, double z, proto::Rigid3* t) {
  const double n = std::sqrt(qw * qw + qz * qz);
  t->mutable_rotation()->set_w(qw / n);
  t->mutable_rotation()->set_z(qz / n);
  t->mutable_translation()->set_x(x);
  t->mutable_translation()->set_y(y);
  t->mutable_translation()->set_z(z);
}

void AddDirection(int axis, double sigma, bool weak, CalibrationResult* r) {
  proto::ObservabilityDirection* d = r->add_observability();
  for (int j = 0; j < 7; ++j) d->add_direction(j == axis ? 1.0 : 0.0);
  d->set_sigma(sigma);
  d->set_weak(weak);
  d->set_description("direction " + std::to_string(axis) + (weak ? " -- WEAK" : ""));
}

void AddResiduals(const char* type, double rms, CalibrationResult* r) {
  proto::ResidualStatistics* s = r->add_residual_statistics();
  s->set_type(type);
  s->set_count(1000);
  s->set_rms(rms);
  s->set_median_abs(0.674 * rms);
}

// What a good calibration looks like: converged, every direction determined,
// tau inside its bounds, residuals at their noise model, the estimate's map
// as sharp as the rig's, close to the rig, static start.
CalibrationResult CleanResult() {
  CalibrationResult r;
  SetRigid(1.0, 0.0, 0.10, 0.02, 0.30, r.mutable_imu_from_lidar());
  SetRigid(1.0, 0.002, 0.11, 0.02, 0.29, r.mutable_rig_imu_from_lidar());
  r.set_rotation_from_rig_deg(0.23);
  r.set_translation_from_rig_m(0.014);
  r.set_time_offset_s(0.0125);
  r.set_time_offset_lower_bound_s(-0.0025);
  r.set_time_offset_upper_bound_s(0.0275);
  r.mutable_solver()->set_converged(true);
  r.mutable_solver()->set_termination("CONVERGENCE");
  for (int axis = 0; axis < 7; ++axis) AddDirection(axis, 1e-4, false, &r);
  AddResiduals("gyro", 1.0, &r);
  AddResiduals("accel", 1.1, &r);
  AddResiduals("lidar", 1.4, &r);
  r.mutable_map_sharpness_estimate()->set_median_thickness_m(0.020);
  r.mutable_map_sharpness_estimate()->set_planar_surfels(900);
  r.mutable_map_sharpness_estimate()->set_common_surfels(850);
  r.mutable_map_sharpness_rig()->set_median_thickness_m(0.021);
  r.mutable_map_sharpness_rig()->set_planar_surfels(880);
  r.mutable_map_sharpness_rig()->set_common_surfels(850);
  r.set_static_start(true);
  r.set_static_samples(300);
  return r;
}

// The verdict of `r` and its reasons joined by newlines.
std::string Decide(CalibrationResult* r, const proto::VerdictParams& params = Params()) {
  DecideVerdict(params, r);
  std::string reasons;
  for (const std::string& s : r->verdict_reasons()) reasons += s + "\n";
  return reasons;
}

::testing::AssertionResult SuspectWith(CalibrationResult r, const std::string& needle) {
  const std::string reasons = Decide(&r);
  if (r.verdict() != CalibrationResult::SUSPECT) {
    return ::testing::AssertionFailure()
           << "verdict " << CalibrationResult::Verdict_Name(r.verdict()) << ", reasons:\n"
           << reasons;
  }
  if (r.verdict_reasons_size() != 1 || reasons.find(needle) == std::string::npos) {
    return ::testing::AssertionFailure() << "expected one reason with '" << needle << "':\n"
                                         << reasons;
  }
  return ::testing::AssertionSuccess();
}

TEST(VerdictTest, CleanResultIsOkWithoutReasons) {
  CalibrationResult r = CleanResult();
  EXPECT_EQ(Decide(&r), "");
  EXPECT_EQ(r.verdict(), CalibrationResult::OK);
  EXPECT_EQ(FormatVerdict(r, Params()), "verdict OK");
}

TEST(VerdictTest, WeakTranslationIsNamedWithTheRigValue) {
  CalibrationResult r = CleanResult();
  r.mutable_observability(5)->set_weak(true);  // translation along b-z
  r.mutable_observability(5)->set_sigma(0.048);
  const std::string reasons = Decide(&r);
  EXPECT_EQ(r.verdict(), CalibrationResult::WEAK);
  ASSERT_EQ(r.verdict_reasons_size(), 1);
  EXPECT_NE(reasons.find("translation along b (0.00, 0.00, 1.00) taken from the rig (prior): "
                         "0.3000 m there (rig 0.2900 m), sigma 0.0480 m"),
            std::string::npos)
      << reasons;
}

// Without a lever-arm guess (the sequence rig's starting extrinsic says the
// translation is unknown) the weak value is the data's, not the rig's; the
// start and /tf_static are notes printed with the verdict.
TEST(VerdictTest, WeakTranslationWithoutAGuessIsTheMotionsAndNotesArePrinted) {
  CalibrationResult r = CleanResult();
  r.mutable_starting_extrinsic()->set_translation_known(false);
  r.add_verdict_notes("starting extrinsic: no guess");
  r.mutable_observability(5)->set_weak(true);
  r.mutable_observability(5)->set_sigma(0.048);
  const std::string reasons = Decide(&r);
  EXPECT_EQ(r.verdict(), CalibrationResult::WEAK);
  EXPECT_EQ(reasons.find("taken from the rig"), std::string::npos) << reasons;
  EXPECT_NE(reasons.find("translation along b (0.00, 0.00, 1.00) weakly determined by the "
                         "motion (no lever-arm guess in the rig): 0.3000 m, sigma 0.0480 m"),
            std::string::npos)
      << reasons;
  EXPECT_NE(FormatVerdict(r, Params()).find("\n  note: starting extrinsic: no guess"),
            std::string::npos);
}

TEST(VerdictTest, WeakRotationAndTimeOffsetAreNamed) {
  CalibrationResult r = CleanResult();
  r.mutable_observability(2)->set_weak(true);
  r.mutable_observability(6)->set_weak(true);
  const std::string reasons = Decide(&r);
  EXPECT_EQ(r.verdict(), CalibrationResult::WEAK);
  EXPECT_NE(reasons.find("weakly determined (sigma above observability.weak_rotation_sigma_deg): direction 2\n"), std::string::npos) << reasons;
  EXPECT_NE(reasons.find("weakly determined: direction 6\n"), std::string::npos) << reasons;
}

TEST(VerdictTest, TimeOffsetAtEitherBoundIsSuspect) {
  CalibrationResult r = CleanResult();
  r.set_time_offset_s(0.0275);
  EXPECT_TRUE(SuspectWith(r, "time offset at a bound of the solve: tau 27.500 ms, bounds "
                             "[-2.500, 27.500] ms"));
  r.set_time_offset_s(-0.0025 + 5e-6);  // within at_bound_tolerance_s (10 us)
  EXPECT_TRUE(SuspectWith(r, "time offset at a bound"));
  r.set_time_offset_s(-0.0025 + 5e-5);  // 50 us inside: free
  EXPECT_EQ(Decide(&r), "");
}

// The clock drift (time_offset_drift.h): decode's finding makes a single
// tau WEAK; with rho estimated and determined it does not (the numbers are a
// verdict note, added by the stage); rho undetermined is WEAK naming it, rho
// at a bound of the solve SUSPECT.
proto::TimeOffsetDriftReport EstimatedDrift() {
  proto::TimeOffsetDriftReport d;
  d.set_estimated(true);
  d.set_start_time_s(2.0);
  d.set_end_time_s(162.0);
  d.set_reference_time_s(82.0);
  d.set_rate_ppm(50.3);
  d.set_rate_sigma_ppm(0.4);
  d.set_rate_lower_bound_ppm(-2000.0);
  d.set_rate_upper_bound_ppm(2000.0);
  d.set_time_offset_start_s(0.0165);
  d.set_time_offset_end_s(0.0085);
  d.set_time_offset_start_sigma_s(1e-4);
  d.set_time_offset_end_sigma_s(1e-4);
  return d;
}

TEST(VerdictTest, ClockDriftIsWeakUnlessTheRateIsEstimated) {
  CalibrationResult r = CleanResult();
  r.set_clock_drift("the LiDAR clock runs +50.1 ± 0.3 ppm against the IMU's");
  std::string reasons = Decide(&r);
  EXPECT_EQ(r.verdict(), CalibrationResult::WEAK);
  EXPECT_NE(reasons.find("τ is the offset the whole sequence fits best"), std::string::npos)
      << reasons;

  *r.mutable_time_offset_drift() = EstimatedDrift();
  EXPECT_EQ(Decide(&r), "");
  EXPECT_EQ(r.verdict(), CalibrationResult::OK);

  r.mutable_time_offset_drift()->set_weak(true);
  r.mutable_time_offset_drift()->set_rate_sigma_ppm(30.0);
  reasons = Decide(&r);
  EXPECT_EQ(r.verdict(), CalibrationResult::WEAK);
  EXPECT_NE(reasons.find("clock drift not determined by this sequence: the LiDAR clock runs "
                         "+50.3 ± 30.0 ppm"),
            std::string::npos)
      << reasons;
}

TEST(VerdictTest, ClockRateAtABoundIsSuspect) {
  CalibrationResult r = CleanResult();
  *r.mutable_time_offset_drift() = EstimatedDrift();
  r.mutable_time_offset_drift()->set_rate_upper_bound_ppm(50.3);
  EXPECT_TRUE(SuspectWith(r, "clock rate at a bound of the solve: +50.3 ppm"));
  // 0.1 ppm inside the bound is 8 us at the ends of 160 s: within
  // at_bound_tolerance_s (10 us).
  r.mutable_time_offset_drift()->set_rate_upper_bound_ppm(50.4);
  EXPECT_TRUE(SuspectWith(r, "clock rate at a bound"));
  r.mutable_time_offset_drift()->set_rate_upper_bound_ppm(51.0);
  EXPECT_EQ(Decide(&r), "");
}

TEST(VerdictTest, NoConvergenceAndNoCovarianceAreSuspect) {
  CalibrationResult r = CleanResult();
  r.mutable_solver()->set_converged(false);
  r.mutable_solver()->set_termination("NO_CONVERGENCE");
  r.mutable_solver()->set_iterations(240);
  EXPECT_TRUE(SuspectWith(r, "did not converge: NO_CONVERGENCE after 240 iterations"));
  proto::VerdictParams lenient = Params();
  lenient.set_require_convergence(false);
  Decide(&r, lenient);
  EXPECT_EQ(r.verdict(), CalibrationResult::OK);

  CalibrationResult c = CleanResult();
  c.clear_observability();
  c.add_observability()->set_description("covariance: rank deficient Jacobian");
  c.mutable_observability(0)->set_weak(true);
  EXPECT_TRUE(SuspectWith(c, "no covariance: covariance: rank deficient Jacobian"));
}

TEST(VerdictTest, ResidualsFarAboveTheirNoiseModelAreSuspect) {
  for (const char* type : {"gyro", "accel", "lidar", "ground"}) {
    CalibrationResult r = CleanResult();
    AddResiduals(type, 50.0, &r);
    EXPECT_TRUE(SuspectWith(r, std::string(type) + " residuals far above their noise model: RMS "
                                                   "50.00 sigma"))
        << type;
  }
}

TEST(VerdictTest, MapLessSharpThanWithTheRigIsSuspect) {
  CalibrationResult r = CleanResult();
  r.mutable_map_sharpness_estimate()->set_median_thickness_m(0.030);  // 1.43 x the rig's
  EXPECT_TRUE(SuspectWith(r, "less sharp with the estimate than with the rig: over the 850 "
                             "voxels planar in both maps, median surfel thickness 3.00 cm with "
                             "the estimate vs 2.10 cm with the rig (900 and 880 planar surfels)"));
  r.mutable_map_sharpness_estimate()->set_planar_surfels(0);
  EXPECT_TRUE(SuspectWith(r, "no planar surfel"));
}

// Maps without a voxel planar in both have no thickness to compare (0 m):
// the one that kept fewer planar surfels is the smeared one.
TEST(VerdictTest, MapsWithoutCommonVoxelsCompareTheirPlanarSurfels) {
  CalibrationResult r = CleanResult();
  for (proto::MapSharpness* m :
       {r.mutable_map_sharpness_estimate(), r.mutable_map_sharpness_rig()}) {
    m->set_common_surfels(0);
    m->set_median_thickness_m(0.0);
  }
  r.mutable_map_sharpness_estimate()->set_planar_surfels(200);
  EXPECT_TRUE(SuspectWith(r, "no voxel is planar in both maps, and the estimate's has 200 "
                             "planar surfels against the rig's 880"));
  // A large move that the map confirms (the rig's map kept fewer) stays OK.
  r.mutable_map_sharpness_estimate()->set_planar_surfels(900);
  r.mutable_map_sharpness_rig()->set_planar_surfels(40);
  r.set_rotation_from_rig_deg(90.0);
  EXPECT_EQ(Decide(&r), "");
  EXPECT_EQ(r.verdict(), CalibrationResult::OK);
}

TEST(VerdictTest, LargeMoveIsSuspectOnlyWithoutASharperMap) {
  CalibrationResult r = CleanResult();
  SetRigid(0.7071, 0.7071, 0.4, 0.02, 0.30, r.mutable_rig_imu_from_lidar());
  r.set_rotation_from_rig_deg(90.0);
  r.set_translation_from_rig_m(0.3);
  // The map with the rig's extrinsic is smeared: the data support the move.
  r.mutable_map_sharpness_rig()->set_median_thickness_m(0.060);
  EXPECT_EQ(Decide(&r), "");
  EXPECT_EQ(r.verdict(), CalibrationResult::OK);
  const std::string text = FormatVerdict(r, Params());
  EXPECT_NE(text.find("note: moved 90.00 deg and 0.300 m from the rig: rig q (w 0.7071, x "
                      "0.0000, y 0.0000, z 0.7071)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("r (0.4000, 0.0200, 0.3000) m; estimate q (w 1.0000"), std::string::npos)
      << text;
  // As sharp as with the rig: the move is not supported by the data.
  r.mutable_map_sharpness_rig()->set_median_thickness_m(0.0205);
  EXPECT_TRUE(SuspectWith(r, "moved far from the rig but the LiDAR map is not sharper"));
  // Translation alone beyond large_translation_m.
  CalibrationResult t = CleanResult();
  t.set_translation_from_rig_m(0.15);
  EXPECT_TRUE(SuspectWith(t, "moved 0.23 deg and 0.150 m from the rig"));
}

TEST(VerdictTest, HandEyeDisagreementIsSuspect) {
  CalibrationResult r = CleanResult();
  r.set_hand_eye_used(true);
  r.set_hand_eye_disagreement_deg(0.5);
  EXPECT_EQ(Decide(&r), "");
  r.set_hand_eye_disagreement_deg(7.5);
  EXPECT_TRUE(SuspectWith(r, "hand-eye and final rotation disagree by 7.50 deg"));
  r.set_hand_eye_used(false);  // not excited: no hand-eye estimate to compare
  EXPECT_EQ(Decide(&r), "");
}

TEST(VerdictTest, NoStaticStartOrTooFewStaticSamplesAreSuspect) {
  CalibrationResult r = CleanResult();
  r.set_static_start(false);
  EXPECT_TRUE(SuspectWith(r, "no static start"));
  r.set_static_start(true);
  r.set_static_samples(20);
  EXPECT_TRUE(SuspectWith(r, "too few static samples: 20 (at least 100)"));
  proto::VerdictParams lenient = Params();
  lenient.set_require_static_start(false);
  Decide(&r, lenient);
  EXPECT_EQ(r.verdict(), CalibrationResult::OK);
}

TEST(VerdictTest, SuspectReasonsComeBeforeWeakOnes) {
  CalibrationResult r = CleanResult();
  r.mutable_observability(5)->set_weak(true);
  r.set_static_start(false);
  Decide(&r);
  EXPECT_EQ(r.verdict(), CalibrationResult::SUSPECT);
  ASSERT_EQ(r.verdict_reasons_size(), 2);
  EXPECT_NE(r.verdict_reasons(0).find("no static start"), std::string::npos);
  EXPECT_NE(r.verdict_reasons(1).find("taken from the rig"), std::string::npos);
}

TEST(ResidualStatisticsTest, RmsAndMedianOfTheAbsoluteValues) {
  const proto::ResidualStatistics s = SummariseResiduals("gyro", {3.0, -4.0, 0.0, -1.0, 2.0});
  EXPECT_EQ(s.type(), "gyro");
  EXPECT_EQ(s.count(), 5);
  EXPECT_DOUBLE_EQ(s.rms(), std::sqrt(30.0 / 5.0));
  EXPECT_DOUBLE_EQ(s.median_abs(), 2.0);
  EXPECT_EQ(SummariseResiduals("lidar", {}).count(), 0);
}

}  // namespace
}  // namespace tiltcal::calibrate
