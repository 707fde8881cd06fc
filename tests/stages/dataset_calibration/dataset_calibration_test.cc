#include "stages/dataset_calibration/dataset_calibration.h"

#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "common/geometry/so3.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/dataset_calibration/default_params_text.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"

namespace tiltcal::dataset {
namespace {

constexpr double kDegPerRad = 180.0 / M_PI;

proto::DatasetCalibrationParams Params(const std::string& overrides = "") {
  return testing::DefaultParamsWith<proto::DatasetCalibrationParams>(
      dataset_calibration::DefaultParamsText(), overrides);
}

const Rigid3d& Truth() {
  static const Rigid3d truth = [] {
    Rigid3d t;
    t.rotation = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                 Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ());
    t.translation = Eigen::Vector3d(0.2477, -0.0699, -0.4636);
    return t;
  }();
  return truth;
}

// A sequence's calibration whose error is drawn from its covariance: yaw
// (rotation about l-x here, the vertical after C_bl) sigma 0.1 deg, tilt
// 0.01 deg, translation 3 mm, tau 0.1 ms.
SequenceCalibration Sequence(const std::string& name, std::mt19937* rng) {
  Eigen::Matrix<double, 7, 1> sigma;
  sigma << 0.1, 0.01, 0.01, 0.003, 0.003, 0.003, 1e-4;
  sigma.head<3>() /= kDegPerRad;
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, 7, 1> e;
  for (int i = 0; i < 7; ++i) e[i] = sigma[i] * normal(*rng);
  SequenceCalibration s;
  s.name = name;
  s.path = "out/" + name + "/calibration.txtpb";
  Rigid3d x = Truth();
  x.rotation = geometry::BoxPlus(Truth().rotation, -e.head<3>().eval());
  x.translation = Truth().translation - e.segment<3>(3);
  *s.result.mutable_imu_from_lidar() = ToProto(x);
  s.result.set_time_offset_s(0.0125 - e[6]);
  s.result.set_time_offset_sigma_s(sigma[6]);
  for (int i = 0; i < 7; ++i) {
    for (int j = 0; j < 7; ++j) s.result.add_covariance(i == j ? sigma[i] * sigma[i] : 0.0);
  }
  s.result.set_verdict(proto::CalibrationResult::WEAK);
  Rigid3d rig = Truth();
  rig.translation += Eigen::Vector3d(0.02, -0.03, 0.025);
  *s.result.mutable_rig_imu_from_lidar() = ToProto(rig);
  *s.result.mutable_motion_rotation_axis_b() = ToProto(Eigen::Vector3d(0, 0, 1));
  return s;
}

double RotationErrorDeg(const proto::CalibrationResult& r) {
  return Eigen::AngleAxisd(ToEigen(r.imu_from_lidar()).rotation.conjugate() * Truth().rotation)
             .angle() *
         kDegPerRad;
}

TEST(DatasetCalibration, FiveSequencesShrinkTheYawSigmaByRootFive) {
  std::mt19937 rng(3);
  std::vector<SequenceCalibration> sequences;
  for (int i = 1; i <= 5; ++i) sequences.push_back(Sequence("run" + std::to_string(i), &rng));
  proto::CalibrationResult out;
  ASSERT_TRUE(CalibrateDataset(sequences, Params(), &out).ok());
  // Rotation about l-x is the vertical in b (C_bl maps l-x to b-z up to sign).
  EXPECT_NEAR(out.rotation_sigma_deg().x(), 0.1 / std::sqrt(5.0), 1e-6);
  EXPECT_NEAR(out.translation_sigma_m().y(), 0.003 / std::sqrt(5.0), 1e-9);
  EXPECT_LT(RotationErrorDeg(out), 3.0 * 0.1 / std::sqrt(5.0));
  ASSERT_EQ(out.sequences_size(), 5);
  for (const proto::DatasetSequence& s : out.sequences()) {
    EXPECT_TRUE(s.used()) << s.name();
    EXPECT_TRUE(s.consistent()) << s.name() << " " << s.consistency_chi2();
    EXPECT_EQ(s.consistency_dof(), 6);
  }
  EXPECT_EQ(out.verdict(), proto::CalibrationResult::OK);
  // Without shared clocks tau is the weighted mean: here equal weights.
  double mean_tau = 0.0;
  for (const SequenceCalibration& s : sequences) mean_tau += s.result.time_offset_s() / 5.0;
  EXPECT_NEAR(out.time_offset_s(), mean_tau, 1e-12);
}

TEST(DatasetCalibration, AnInconsistentSequenceIsLeftOutAndNamed) {
  std::mt19937 rng(4);
  std::vector<SequenceCalibration> sequences;
  for (int i = 1; i <= 5; ++i) sequences.push_back(Sequence("run" + std::to_string(i), &rng));
  // run4's rig moved: its extrinsic is 1 deg off in tilt (100 sigma).
  Rigid3d bumped = ToEigen(sequences[3].result.imu_from_lidar());
  bumped.rotation = geometry::BoxPlus(bumped.rotation, Eigen::Vector3d(0, 1.0 / kDegPerRad, 0));
  *sequences[3].result.mutable_imu_from_lidar() = ToProto(bumped);
  proto::CalibrationResult out;
  ASSERT_TRUE(CalibrateDataset(sequences, Params(), &out).ok());
  EXPECT_FALSE(out.sequences(3).used());
  EXPECT_FALSE(out.sequences(3).consistent());
  EXPECT_NE(out.sequences(3).reason().find("inconsistent"), std::string::npos);
  EXPECT_NE(out.sequences(3).disagreement().find("rotation about l-y"), std::string::npos)
      << out.sequences(3).disagreement();
  for (int i : {0, 1, 2, 4}) EXPECT_TRUE(out.sequences(i).used()) << i;
  EXPECT_LT(RotationErrorDeg(out), 3.0 * 0.1 / std::sqrt(4.0));
  bool named = false;
  for (const std::string& r : out.verdict_reasons()) named |= r.find("left out run4") == 0;
  EXPECT_TRUE(named);

  // Without auto_exclude it stays in and pulls the joint value.
  proto::CalibrationResult kept;
  ASSERT_TRUE(CalibrateDataset(sequences, Params("consistency { auto_exclude: false }"), &kept).ok());
  EXPECT_TRUE(kept.sequences(3).used());
  EXPECT_FALSE(kept.sequences(3).consistent());
  EXPECT_GT(RotationErrorDeg(kept), 0.15);
}

TEST(DatasetCalibration, UserExclusionSuspectInputsAndTooFewSequences) {
  std::mt19937 rng(5);
  std::vector<SequenceCalibration> sequences = {Sequence("a", &rng), Sequence("b", &rng),
                                                Sequence("c", &rng)};
  sequences[1].result.set_verdict(proto::CalibrationResult::SUSPECT);
  proto::CalibrationResult out;
  ASSERT_TRUE(CalibrateDataset(sequences, Params("exclude_sequences: \"c\""), &out).ok());
  EXPECT_EQ(out.sequences(1).reason(), "verdict SUSPECT");
  EXPECT_EQ(out.sequences(2).reason(), "left out by exclude_sequences");
  // One sequence left, two required: SUSPECT, and the value is a's.
  EXPECT_EQ(out.verdict(), proto::CalibrationResult::SUSPECT);
  EXPECT_NE(out.verdict_reasons(0).find("only 1 sequence(s) used"), std::string::npos);
  EXPECT_LT(Eigen::AngleAxisd(ToEigen(out.imu_from_lidar()).rotation.conjugate() *
                              ToEigen(sequences[0].result.imu_from_lidar()).rotation)
                .angle(),
            1e-12);

  sequences[0].result.clear_covariance();
  const Status status = CalibrateDataset(sequences, Params("exclude_sequences: \"c\""), &out);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("a: no covariance"), std::string::npos) << status.message();
}

// Each solve's prior on the translation along the rotation axis counts once.
TEST(DatasetCalibration, TheTranslationPriorCountsOnce) {
  std::mt19937 rng(6);
  std::vector<SequenceCalibration> sequences;
  for (int i = 1; i <= 4; ++i) {
    SequenceCalibration s = Sequence("run" + std::to_string(i), &rng);
    // The vertical held only by a 5 cm prior: variance 0.05^2 along b-z.
    s.result.set_covariance(5 * 7 + 5, 0.05 * 0.05);
    s.result.set_translation_prior_sigma_m(0.05);
    *s.result.mutable_translation_prior_axis_b() = ToProto(Eigen::Vector3d(0, 0, 1));
    sequences.push_back(s);
  }
  proto::CalibrationResult out;
  ASSERT_TRUE(CalibrateDataset(sequences, Params(), &out).ok());
  EXPECT_NEAR(out.translation_sigma_m().z(), 0.05, 1e-6);
  EXPECT_EQ(out.verdict(), proto::CalibrationResult::WEAK);
}

TEST(DatasetCalibration, ToolWritesTheResultAndExitsThreeWhenSuspect) {
  testing::TempDir dir;
  std::mt19937 rng(7);
  std::string args;
  for (const char* name : {"run1", "run2"}) {
    std::filesystem::create_directories(dir.File(name));
    ASSERT_TRUE(WriteTextProto(dir.File(std::string(name) + "/calibration.txtpb"),
                               Sequence(name, &rng).result)
                    .ok());
    args += " " + dir.File(std::string(name) + "/calibration.txtpb");
  }
  const std::string tool = testing::ToolPath("tiltcal_dataset_calibration");
  std::string output;
  EXPECT_EQ(testing::RunCommand(tool + " --out=" + dir.File("calibration.txtpb") + args, &output),
            0)
      << output;
  proto::CalibrationResult out;
  ASSERT_TRUE(ReadTextProto(dir.File("calibration.txtpb"), &out).ok());
  EXPECT_EQ(out.sequences_size(), 2);
  EXPECT_EQ(out.sequences(0).name(), "run1");
  EXPECT_NE(output.find("joint C_bl"), std::string::npos) << output;

  std::string params_text(dataset_calibration::DefaultParamsText());
  const std::string two = "min_sequences: 2";
  ASSERT_NE(params_text.find(two), std::string::npos);
  params_text.replace(params_text.find(two), two.size(), "min_sequences: 3");
  ASSERT_TRUE(WriteFileAtomically(dir.File("params.txtpb"), params_text).ok());
  EXPECT_EQ(testing::RunCommand(tool + " --params=" + dir.File("params.txtpb") + " --out=" +
                                    dir.File("suspect.txtpb") + args,
                                &output),
            3)
      << output;
  EXPECT_TRUE(testing::FileExists(dir.File("suspect.txtpb")));
}

}  // namespace
}  // namespace tiltcal::dataset
