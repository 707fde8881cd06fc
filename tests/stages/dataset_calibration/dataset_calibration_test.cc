#include "stages/dataset_calibration/dataset_calibration.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/geometry/so3.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/dataset_calibration/default_params_text.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"

namespace tiltcal::dataset {
namespace {

using geometry::kDegPerRad;

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
  ASSERT_TRUE(
      CalibrateDataset(sequences, Params("consistency { auto_exclude: false }"), &kept).ok());
  EXPECT_TRUE(kept.sequences(3).used());
  EXPECT_FALSE(kept.sequences(3).consistent());
  EXPECT_GT(RotationErrorDeg(kept), 0.15);
  // ... and the joint value is not to be used without reading why.
  EXPECT_EQ(kept.verdict(), proto::CalibrationResult::SUSPECT);
  ASSERT_GT(kept.verdict_reasons_size(), 0);
  EXPECT_NE(kept.verdict_reasons(0).find("run4 chi2"), std::string::npos)
      << kept.verdict_reasons(0);
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
  // One sequence left: the dataset's result is a's, with a's verdict.
  EXPECT_EQ(out.verdict(), proto::CalibrationResult::WEAK);
  EXPECT_EQ(out.verdict_reasons(0), "one sequence: no consistency check between sequences");
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

// The tool on sequences written to <dir>/<name>/calibration.txtpb.
class DatasetTool {
 public:
  std::string Write(const std::string& name, const proto::CalibrationResult& result) {
    std::filesystem::create_directories(dir_.File(name));
    const std::string path = dir_.File(name + "/calibration.txtpb");
    EXPECT_TRUE(WriteTextProto(path, result).ok());
    return path;
  }
  // Exit code; the output's text in *output, the result in *out (when written).
  int Run(const std::vector<std::string>& paths, std::string* output,
          proto::CalibrationResult* out, const std::string& params = "") {
    std::string command = testing::ToolPath("tiltcal_dataset_calibration") +
                          " --out=" + dir_.File("calibration.txtpb");
    if (!params.empty()) command += " --params=" + params;
    for (const std::string& p : paths) command += " " + p;
    std::filesystem::remove(dir_.File("calibration.txtpb"));
    const int code = testing::RunCommand(command, output);
    if (testing::FileExists(dir_.File("calibration.txtpb"))) {
      EXPECT_TRUE(ReadTextProto(dir_.File("calibration.txtpb"), out).ok());
    }
    return code;
  }
  std::string File(const std::string& name) const { return dir_.File(name); }

 private:
  testing::TempDir dir_;
};

bool AllFinite(const proto::CalibrationResult& r) {
  const auto& q = r.imu_from_lidar().rotation();
  const auto& t = r.imu_from_lidar().translation();
  bool finite = true;
  for (double v : {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z(), r.time_offset_s(),
                   r.time_offset_sigma_s(), r.rotation_sigma_deg().x(),
                   r.translation_sigma_m().z()}) {
    finite = finite && std::isfinite(v);
  }
  for (double v : r.covariance()) finite = finite && std::isfinite(v);
  return finite;
}

double AngleDeg(const proto::CalibrationResult& a, const proto::CalibrationResult& b) {
  return Eigen::AngleAxisd(ToEigen(a.imu_from_lidar()).rotation.conjugate() *
                           ToEigen(b.imu_from_lidar()).rotation)
             .angle() *
         kDegPerRad;
}

// Two sequences 30 deg apart fail the consistency test and neither can be
// left out (min_sequences 2): the joint value between them is SUSPECT, exit 3.
TEST(DatasetCalibration, TwoDisagreeingSequencesAreSuspect) {
  std::mt19937 rng(11);
  SequenceCalibration run1 = Sequence("run1", &rng);
  SequenceCalibration run2 = Sequence("run2", &rng);
  Rigid3d turned = ToEigen(run2.result.imu_from_lidar());
  turned.rotation =
      turned.rotation * Eigen::AngleAxisd(30.0 / kDegPerRad, Eigen::Vector3d::UnitZ());
  *run2.result.mutable_imu_from_lidar() = ToProto(turned);
  DatasetTool tool;
  const std::vector<std::string> paths = {tool.Write("run1", run1.result),
                                          tool.Write("run2", run2.result)};
  std::string output;
  proto::CalibrationResult out;
  EXPECT_EQ(tool.Run(paths, &output, &out), 3) << output;
  EXPECT_EQ(out.verdict(), proto::CalibrationResult::SUSPECT) << output;
  ASSERT_GT(out.verdict_reasons_size(), 0) << output;
  const std::string& reason = out.verdict_reasons(0);
  for (const char* part : {"disagree", "run1 chi2", "run2 chi2", "> 22.", " deg (run1 and run2)"}) {
    EXPECT_NE(reason.find(part), std::string::npos) << part << " in " << reason;
  }
  const std::string angle = "largest angle between two used extrinsics ";
  ASSERT_NE(reason.find(angle), std::string::npos) << reason;
  EXPECT_NEAR(std::stod(reason.substr(reason.find(angle) + angle.size())), 30.0, 0.01) << reason;
  EXPECT_TRUE(out.sequences(0).used());
  EXPECT_TRUE(out.sequences(1).used());
}

// The reason names the two used extrinsics furthest apart, whichever they are.
TEST(DatasetCalibration, TheDisagreementNamesTheWidestPair) {
  std::mt19937 rng(17);
  std::vector<SequenceCalibration> sequences = {Sequence("a", &rng), Sequence("b", &rng),
                                                Sequence("c", &rng)};
  Rigid3d turned = ToEigen(sequences[0].result.imu_from_lidar());
  turned.rotation = turned.rotation * Eigen::AngleAxisd(5.0 / kDegPerRad, Eigen::Vector3d::UnitY());
  *sequences[0].result.mutable_imu_from_lidar() = ToProto(turned);
  proto::CalibrationResult out;
  ASSERT_TRUE(
      CalibrateDataset(sequences, Params("consistency { auto_exclude: false }"), &out).ok());
  EXPECT_EQ(out.verdict(), proto::CalibrationResult::SUSPECT);
  ASSERT_GT(out.verdict_reasons_size(), 0);
  const std::string& reason = out.verdict_reasons(0);
  const std::string angle = "largest angle between two used extrinsics ";
  ASSERT_NE(reason.find(angle), std::string::npos) << reason;
  EXPECT_NEAR(std::stod(reason.substr(reason.find(angle) + angle.size())), 5.0, 0.05) << reason;
  EXPECT_NE(reason.find(" deg (a and "), std::string::npos) << reason;
}

// A calibration file that is broken, each way, beside two good ones.
struct BrokenFile {
  const char* what;
  const char* reason;  // part of the reason it is refused
  void (*breaks)(proto::CalibrationResult*);
};

void ScaleCovariance(proto::CalibrationResult* r, double factor) {
  for (int k = 0; k < r->covariance_size(); ++k) r->set_covariance(k, r->covariance(k) * factor);
}

const std::vector<BrokenFile>& BrokenFiles() {
  static const std::vector<BrokenFile> files = {
      {"w nan", "imu_from_lidar.rotation (w nan",
       [](proto::CalibrationResult* r) {
         r->mutable_imu_from_lidar()->mutable_rotation()->set_w(std::nan(""));
       }},
      {"empty imu_from_lidar", "imu_from_lidar.rotation is missing",
       [](proto::CalibrationResult* r) { r->clear_imu_from_lidar(); }},
      {"quaternion of norm 1.1", "not a unit quaternion (norm 1.1",
       [](proto::CalibrationResult* r) {
         proto::Quaternion* q = r->mutable_imu_from_lidar()->mutable_rotation();
         q->set_w(q->w() * 1.1);
         q->set_x(q->x() * 1.1);
         q->set_y(q->y() * 1.1);
         q->set_z(q->z() * 1.1);
       }},
      {"tau nan", "time_offset_s = nan",
       [](proto::CalibrationResult* r) { r->set_time_offset_s(std::nan("")); }},
      {"tau sigma nan", "time_offset_sigma_s = nan",
       [](proto::CalibrationResult* r) { r->set_time_offset_sigma_s(std::nan("")); }},
      {"tau sigma negative", "time_offset_sigma_s = -0.001",
       [](proto::CalibrationResult* r) { r->set_time_offset_sigma_s(-0.001); }},
      {"covariance all zero", "is zero",
       [](proto::CalibrationResult* r) { ScaleCovariance(r, 0.0); }},
      {"covariance negative definite", "not positive definite",
       [](proto::CalibrationResult* r) { ScaleCovariance(r, -1.0); }},
      {"covariance scaled by 1e-300", "smallest sigma",
       [](proto::CalibrationResult* r) { ScaleCovariance(r, 1e-300); }},
      {"covariance infinite", "covariance[8] = inf",
       [](proto::CalibrationResult* r) { r->set_covariance(8, HUGE_VAL); }},
      {"covariance asymmetric", "not symmetric",
       [](proto::CalibrationResult* r) { r->set_covariance(0 * 7 + 3, 1e-6); }},
      {"covariance ill-conditioned", "condition number",
       [](proto::CalibrationResult* r) {
         r->set_covariance(1 * 7 + 1, 1e-12);
         r->set_covariance(5 * 7 + 5, 100.0);
       }},
      {"covariance of 48 values", "48 values",
       [](proto::CalibrationResult* r) { r->mutable_covariance()->RemoveLast(); }},
      {"a prior stronger than the covariance", "less information than its own translation prior",
       [](proto::CalibrationResult* r) {
         r->set_translation_prior_sigma_m(1e-4);
         *r->mutable_translation_prior_axis_b() = ToProto(Eigen::Vector3d(0, 0, 1));
       }},
      {"verdict unset", "verdict 0 is not OK, WEAK or SUSPECT",
       [](proto::CalibrationResult* r) {
         r->set_verdict(proto::CalibrationResult::VERDICT_UNSET);
       }},
  };
  return files;
}

TEST(DatasetCalibration, BrokenSequenceFilesAreRefusedAndNamed) {
  std::mt19937 rng(12);
  const SequenceCalibration a = Sequence("a", &rng);
  const SequenceCalibration b = Sequence("b", &rng);
  proto::CalibrationResult good;  // a and b alone
  ASSERT_TRUE(CalibrateDataset({a, b}, Params(), &good).ok());
  const SequenceCalibration c_good = Sequence("c", &rng);
  for (const BrokenFile& broken : BrokenFiles()) {
    SCOPED_TRACE(broken.what);
    proto::CalibrationResult c = c_good.result;
    broken.breaks(&c);
    DatasetTool tool;
    const std::string c_path = tool.Write("c", c);
    std::string output;
    proto::CalibrationResult out;
    // Beside two good sequences: left out, named with its file; the joint
    // value is a's and b's.
    const std::vector<std::string> three = {tool.Write("a", a.result), tool.Write("b", b.result),
                                            c_path};
    EXPECT_EQ(tool.Run(three, &output, &out), 0) << output;
    ASSERT_EQ(out.sequences_size(), 3) << output;
    EXPECT_FALSE(out.sequences(2).used());
    EXPECT_NE(out.sequences(2).reason().find(c_path + ": "), std::string::npos)
        << out.sequences(2).reason();
    EXPECT_NE(out.sequences(2).reason().find(broken.reason), std::string::npos)
        << out.sequences(2).reason();
    EXPECT_TRUE(out.sequences(0).used() && out.sequences(1).used());
    EXPECT_TRUE(AllFinite(out));
    EXPECT_LT(AngleDeg(out, good), 1e-9);
    EXPECT_NEAR(ToEigen(out.imu_from_lidar().translation()).x(),
                ToEigen(good.imu_from_lidar().translation()).x(), 1e-12);
    bool named = false;
    for (const std::string& r : out.verdict_reasons()) {
      named |= r.find("left out c: " + c_path) == 0;
    }
    EXPECT_TRUE(named) << output;

    // Beside one good sequence: that sequence is the dataset's result.
    EXPECT_EQ(tool.Run({three[0], c_path}, &output, &out), 0) << output;
    EXPECT_LT(AngleDeg(out, a.result), 1e-9);
    EXPECT_TRUE(AllFinite(out));
    EXPECT_EQ(out.verdict_reasons(0), "one sequence: no consistency check between sequences");

    // Alone: nothing to use, an error naming it, no output.
    EXPECT_EQ(tool.Run({c_path}, &output, &out), 1) << output;
    EXPECT_NE(output.find(c_path), std::string::npos) << output;
    EXPECT_FALSE(testing::FileExists(tool.File("calibration.txtpb")));
  }
}

// With shared clocks tau is fused: a solve that held tau (zero variance)
// cannot be, and is refused.
TEST(DatasetCalibration, HeldTauIsRefusedWhenTheClocksAreShared) {
  std::mt19937 rng(13);
  std::vector<SequenceCalibration> sequences = {Sequence("a", &rng), Sequence("b", &rng),
                                                Sequence("c", &rng)};
  sequences[2].result.set_covariance(48, 0.0);
  proto::CalibrationResult out;
  ASSERT_TRUE(CalibrateDataset(sequences, Params("time_offset_shared: true"), &out).ok());
  EXPECT_FALSE(out.sequences(2).used());
  EXPECT_NE(out.sequences(2).reason().find("7x7 block) is not positive definite"),
            std::string::npos)
      << out.sequences(2).reason();
  // Each clock its own: the 6x6 block is fused, c is used.
  ASSERT_TRUE(CalibrateDataset(sequences, Params(), &out).ok());
  EXPECT_TRUE(out.sequences(2).used()) << out.sequences(2).reason();
}

TEST(DatasetCalibration, InputCheckParamsAreValidated) {
  std::mt19937 rng(14);
  proto::CalibrationResult out;
  const Status status = CalibrateDataset(
      {Sequence("a", &rng)}, Params("input { min_sigma: 0.5 max_sigma: 0.1 }"), &out);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("input.min_sigma"), std::string::npos) << status.message();
}

// One sequence is a dataset: its result, its verdict, exit 0 when OK or WEAK.
TEST(DatasetCalibration, OneSequenceIsADataset) {
  std::mt19937 rng(15);
  for (const auto verdict : {proto::CalibrationResult::OK, proto::CalibrationResult::WEAK}) {
    SequenceCalibration run = Sequence("run1", &rng);
    run.result.set_verdict(verdict);
    run.result.add_verdict_reasons("a reason of its own");
    DatasetTool tool;
    std::string output;
    proto::CalibrationResult out;
    EXPECT_EQ(tool.Run({tool.Write("run1", run.result)}, &output, &out), 0) << output;
    EXPECT_EQ(out.verdict(), verdict) << output;
    ASSERT_GE(out.verdict_reasons_size(), 2) << output;
    EXPECT_EQ(out.verdict_reasons(0), "one sequence: no consistency check between sequences");
    EXPECT_NE(std::find(out.verdict_reasons().begin(), out.verdict_reasons().end(),
                        "a reason of its own"),
              out.verdict_reasons().end());
    EXPECT_LT(AngleDeg(out, run.result), 1e-9);
    EXPECT_NEAR(out.time_offset_s(), run.result.time_offset_s(), 1e-15);
    EXPECT_NEAR(out.translation_sigma_m().y(), 0.003, 1e-12);
    ASSERT_EQ(out.sequences_size(), 1);
    EXPECT_TRUE(out.sequences(0).used());
  }
}

// The params file is read strictly: a field given twice is refused even when
// its first value is the default.
TEST(DatasetCalibration, ParamsWithAFieldGivenTwiceAreRefused) {
  std::mt19937 rng(16);
  DatasetTool tool;
  const std::string run = tool.Write("run1", Sequence("run1", &rng).result);
  const std::string params = tool.File("params.txtpb");
  ASSERT_TRUE(WriteFileAtomically(params, std::string(dataset_calibration::DefaultParamsText()) +
                                              "time_offset_shared: true\n")
                  .ok());
  std::string output;
  proto::CalibrationResult out;
  EXPECT_EQ(tool.Run({run}, &output, &out, params), 1) << output;
  EXPECT_NE(output.find(params + ": line "), std::string::npos) << output;
  EXPECT_NE(output.find("field time_offset_shared is given twice"), std::string::npos) << output;
}

}  // namespace
}  // namespace tiltcal::dataset
