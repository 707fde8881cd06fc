#include "stages/verify/reference_comparison.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "stages/verify/default_params_text.h"
#include "tests/testing/params_text.h"

namespace tiltcal::verify {
namespace {

using geometry::kRadPerDeg;

proto::VerifyParams Params(const std::string& overrides = "") {
  return testing::DefaultParamsWith<proto::VerifyParams>(DefaultParamsText(), overrides);
}

// The simulated rig's extrinsic: IMU z down, LiDAR turned about it.
Rigid3d Truth() {
  Rigid3d t;
  t.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
               Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ());
  t.translation = Eigen::Vector3d(0.2477, -0.0699, -0.4636);
  return t;
}

// A calibration with a diagonal covariance (rotation sigma in deg about the
// axes of l, translation in m along b, tau in s) and no prior.
proto::CalibrationResult Calibration(const Rigid3d& extrinsic, double tau_s,
                                     const Eigen::Vector3d& rotation_sigma_deg,
                                     const Eigen::Vector3d& translation_sigma_m,
                                     double tau_sigma_s) {
  proto::CalibrationResult r;
  *r.mutable_imu_from_lidar() = ToProto(extrinsic);
  *r.mutable_rig_imu_from_lidar() = ToProto(extrinsic);
  r.set_time_offset_s(tau_s);
  r.set_time_offset_sigma_s(tau_sigma_s);
  Eigen::Matrix<double, 7, 1> sigma;
  sigma << rotation_sigma_deg * kRadPerDeg, translation_sigma_m, tau_sigma_s;
  for (int i = 0; i < 7; ++i) {
    for (int j = 0; j < 7; ++j) r.add_covariance(i == j ? sigma[i] * sigma[i] : 0.0);
  }
  r.set_verdict(proto::CalibrationResult::OK);
  return r;
}

// A 40 s sequence's estimate: 0.03 deg, 3 mm, 0.2 ms.
proto::CalibrationResult Sequence(const Rigid3d& extrinsic, double tau_s = 0.0125) {
  return Calibration(extrinsic, tau_s, Eigen::Vector3d::Constant(0.03),
                     Eigen::Vector3d::Constant(0.003), 2e-4);
}

// A reference from several sequences: half the sigma.
proto::CalibrationResult Reference(const Rigid3d& extrinsic, double tau_s = 0.0125) {
  return Calibration(extrinsic, tau_s, Eigen::Vector3d::Constant(0.015),
                     Eigen::Vector3d::Constant(0.0015), 1e-4);
}

// The LiDAR turned by angle_deg about axis_b (frame b), as a bump does.
Rigid3d Turned(const Rigid3d& x, const Eigen::Vector3d& axis_b, double angle_deg) {
  Rigid3d y = x;
  y.rotation = Eigen::AngleAxisd(angle_deg * kRadPerDeg, axis_b.normalized()) * x.rotation;
  return y;
}

std::string Reasons(const proto::SequenceVerification& s) {
  std::string out;
  for (const std::string& r : s.reasons()) out += r + "\n";
  return out;
}

TEST(ReferenceComparison, TheSameExtrinsicHolds) {
  proto::SequenceVerification out;
  CompareWithReference(Sequence(Truth()), Reference(Truth()), Params(), &out);
  EXPECT_EQ(out.verdict(), proto::VerifyResult::HOLDS) << Reasons(out);
  EXPECT_EQ(out.dof(), 7);
  EXPECT_NEAR(out.chi2(), 0.0, 1e-9);
  EXPECT_GT(out.limit(), 20.0);
  // The smallest detected move: sqrt(limit) sigma of the difference.
  const double sigma_deg = std::sqrt(0.03 * 0.03 + 0.015 * 0.015);
  EXPECT_NEAR(out.detectable_rotation_deg().z(), std::sqrt(out.limit()) * sigma_deg, 1e-6);
  EXPECT_NEAR(out.detectable_translation_m().x(),
              std::sqrt(out.limit()) * std::sqrt(0.003 * 0.003 + 0.0015 * 0.0015), 1e-9);
}

TEST(ReferenceComparison, AOneDegreeYawIsAMoveAboutBz) {
  proto::SequenceVerification out;
  CompareWithReference(Sequence(Turned(Truth(), Eigen::Vector3d::UnitZ(), 1.0)),
                       Reference(Truth()), Params(), &out);
  ASSERT_EQ(out.verdict(), proto::VerifyResult::MOVED) << Reasons(out);
  EXPECT_NEAR(out.rotation_difference_deg().z(), 1.0, 1e-9);
  EXPECT_NEAR(out.rotation_difference_deg().x(), 0.0, 1e-9);
  EXPECT_NEAR(out.rotation_difference_sigma(), 1.0 / std::sqrt(0.03 * 0.03 + 0.015 * 0.015),
              1e-6);
  const std::string reasons = Reasons(out);
  EXPECT_NE(reasons.find("moved: rotation 1.000 deg about b (0.00, 0.00, 1.00)"),
            std::string::npos)
      << reasons;
  EXPECT_EQ(reasons.find("moved: translation"), std::string::npos) << reasons;
}

TEST(ReferenceComparison, ThreeCentimetresAlongBxAndTwoMillisecondsAreNamed) {
  Rigid3d moved = Truth();
  moved.translation.x() += 0.03;
  proto::SequenceVerification out;
  CompareWithReference(Sequence(moved, 0.0125 + 0.002), Reference(Truth()), Params(), &out);
  ASSERT_EQ(out.verdict(), proto::VerifyResult::MOVED) << Reasons(out);
  const std::string reasons = Reasons(out);
  EXPECT_NE(reasons.find("moved: translation 30.0 mm along b (1.00, 0.00, 0.00)"),
            std::string::npos)
      << reasons;
  EXPECT_NE(reasons.find("moved: tau +2.000 ms"), std::string::npos) << reasons;
  EXPECT_EQ(reasons.find("moved: rotation"), std::string::npos) << reasons;
}

// Clocks that differ between recordings: tau is shown, not tested.
TEST(ReferenceComparison, TauIsNotTestedWhenTheClocksAreNotShared) {
  proto::SequenceVerification out;
  CompareWithReference(Sequence(Truth(), 0.0125 + 0.01), Reference(Truth()),
                       Params("compare_time_offset: false"), &out);
  EXPECT_EQ(out.verdict(), proto::VerifyResult::HOLDS) << Reasons(out);
  EXPECT_EQ(out.dof(), 6);
}

// A sequence that turned too little to fix the yaw (sigma 0.5 deg about l-z,
// the vertical b-z after C_bl): a 0.3 deg bump would go unnoticed, so it
// cannot tell, even though nothing moved; never HOLDS.
TEST(ReferenceComparison, AWeakYawCannotTellAndNamesTheDirection) {
  proto::CalibrationResult weak = Calibration(Truth(), 0.0125, Eigen::Vector3d(0.03, 0.03, 0.5),
                                              Eigen::Vector3d::Constant(0.003), 2e-4);
  proto::SequenceVerification out;
  CompareWithReference(weak, Reference(Truth()), Params(), &out);
  ASSERT_EQ(out.verdict(), proto::VerifyResult::CANNOT_TELL) << Reasons(out);
  const std::string reasons = Reasons(out);
  EXPECT_NE(reasons.find("cannot tell: a rotation about b (0.00, 0.00, 1.00) below"),
            std::string::npos)
      << reasons;
  // A move larger than what it can see is still a move.
  CompareWithReference(Calibration(Turned(Truth(), Eigen::Vector3d::UnitX(), 1.0), 0.0125,
                                   Eigen::Vector3d(0.03, 0.03, 0.5),
                                   Eigen::Vector3d::Constant(0.003), 2e-4),
                       Reference(Truth()), Params(), &out);
  EXPECT_EQ(out.verdict(), proto::VerifyResult::MOVED) << Reasons(out);
}

// The vertical lever arm held only by the solve's prior (no distance
// residual): the prior is not data, so the sequence cannot tell whether the
// LiDAR moved up or down, although its value equals the reference's.
TEST(ReferenceComparison, ADirectionOnlyThePriorHeldCannotTell) {
  proto::CalibrationResult s = Calibration(Truth(), 0.0125, Eigen::Vector3d::Constant(0.03),
                                           Eigen::Vector3d(0.003, 0.003, 0.05), 2e-4);
  s.set_translation_prior_sigma_m(0.05);
  *s.mutable_translation_prior_axis_b() = ToProto(Eigen::Vector3d::UnitZ());
  proto::SequenceVerification out;
  CompareWithReference(s, Reference(Truth()), Params(), &out);
  ASSERT_EQ(out.verdict(), proto::VerifyResult::CANNOT_TELL) << Reasons(out);
  EXPECT_EQ(out.dof(), 6);
  EXPECT_EQ(out.detectable_translation_m().z(), 0.0);
  const std::string reasons = Reasons(out);
  EXPECT_NE(reasons.find("cannot tell: no translation along b (0.00, 0.00, 1.00) is detected"),
            std::string::npos)
      << reasons;
}

TEST(ReferenceComparison, ASuspectCalibrationCannotTell) {
  proto::CalibrationResult s = Sequence(Truth());
  s.set_verdict(proto::CalibrationResult::SUSPECT);
  s.add_verdict_reasons("tau at its bound");
  proto::SequenceVerification out;
  CompareWithReference(s, Reference(Truth()), Params(), &out);
  EXPECT_EQ(out.verdict(), proto::VerifyResult::CANNOT_TELL);
  EXPECT_NE(Reasons(out).find("SUSPECT: tau at its bound"), std::string::npos) << Reasons(out);
  s = Sequence(Truth());
  s.clear_covariance();
  CompareWithReference(s, Reference(Truth()), Params(), &out);
  EXPECT_EQ(out.verdict(), proto::VerifyResult::CANNOT_TELL);
  EXPECT_NE(Reasons(out).find("cannot be compared: covariance has 0 values"), std::string::npos)
      << Reasons(out);
}

proto::VerifyResult Dataset(std::initializer_list<proto::VerifyResult::Verdict> verdicts) {
  proto::VerifyResult r;
  int i = 0;
  for (proto::VerifyResult::Verdict v : verdicts) {
    proto::SequenceVerification* s = r.add_sequences();
    s->set_name("seq_" + std::to_string(++i));
    s->set_verdict(v);
    s->add_reasons(proto::VerifyResult::Verdict_Name(v));
  }
  DecideDatasetVerdict(&r);
  return r;
}

TEST(ReferenceComparison, TheDatasetMovedWhenOneMovedAndHoldsOnlyWhenOneDecided) {
  using V = proto::VerifyResult;
  EXPECT_EQ(Dataset({V::HOLDS, V::MOVED, V::CANNOT_TELL}).verdict(), V::MOVED);
  const proto::VerifyResult moved = Dataset({V::HOLDS, V::MOVED});
  EXPECT_EQ(moved.verdict_reasons(0), "seq_2: MOVED");
  EXPECT_EQ(Dataset({V::CANNOT_TELL, V::HOLDS}).verdict(), V::HOLDS);
  EXPECT_EQ(Dataset({V::CANNOT_TELL, V::HOLDS}).verdict_reasons(1), "cannot tell on seq_1");
  EXPECT_EQ(Dataset({V::CANNOT_TELL, V::CANNOT_TELL}).verdict(), V::CANNOT_TELL);
  EXPECT_EQ(Dataset({}).verdict(), V::CANNOT_TELL);
}

}  // namespace
}  // namespace tiltcal::verify
