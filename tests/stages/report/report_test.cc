#include "stages/report/report.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include <Eigen/Geometry>

#include <gtest/gtest.h>

#include "common/geometry/angles.h"
#include "common/geometry/euler_angles.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "tests/stages/report/report_params_text.h"
#include "tests/testing/test_env.h"

namespace tiltcal::report {
namespace {

proto::Rigid3 Extrinsic(const Eigen::Vector3d& euler_deg, const Eigen::Vector3d& t_m) {
  Rigid3d t;
  t.rotation = Eigen::Quaterniond(geometry::RotationFromEuler123(euler_deg * geometry::kRadPerDeg));
  t.translation = t_m;
  return ToProto(t);
}

SequenceResult Sequence(const std::string& name, const Eigen::Vector3d& euler_deg,
                        const Eigen::Vector3d& t_m, double tau_s) {
  SequenceResult s;
  s.name = name;
  *s.calibration.mutable_imu_from_lidar() = Extrinsic(euler_deg, t_m);
  s.calibration.set_time_offset_s(tau_s);
  return s;
}

TEST(Repeatability, HandComputedMeansSigmasAndErrors) {
  // Yaw 179, -179 and 180 deg: SO(3) mean 180 deg, deviations -1, +1, 0 deg
  // about z -> σ_3 = sqrt((1 + 1 + 0) / 2) = 1 deg.
  std::vector<SequenceResult> results = {
      Sequence("a", {0, 0, 179}, {0.10, 0.20, 0.30}, 0.010),
      Sequence("b", {0, 0, -179}, {0.12, 0.20, 0.34}, 0.012),
      Sequence("c", {0, 0, 180}, {0.14, 0.20, 0.32}, 0.014),
  };
  proto::SimulationTruth truth;
  *truth.mutable_imu_from_lidar() = Extrinsic({0, 0, 180}, {0.12, 0.21, 0.30});
  truth.set_time_offset_s(0.011);
  for (auto& r : results) r.truth = truth;

  const Repeatability rep = ComputeRepeatability(results, nullptr);
  ASSERT_EQ(rep.sequences.size(), 3u);
  EXPECT_NEAR(std::abs(rep.mean.euler123_deg.z()), 180.0, 1e-9);
  EXPECT_NEAR(rep.mean.euler123_deg.x(), 0.0, 1e-9);
  EXPECT_NEAR(rep.sigma.euler123_deg.z(), 1.0, 1e-9);
  EXPECT_NEAR(rep.sigma.euler123_deg.x(), 0.0, 1e-9);
  // Translation mean (12, 20, 32) cm, sample σ (2, 0, 2) cm.
  EXPECT_TRUE(rep.mean.translation_cm.isApprox(Eigen::Vector3d(12, 20, 32), 1e-12));
  EXPECT_NEAR(rep.sigma.translation_cm.x(), 2.0, 1e-12);
  EXPECT_NEAR(rep.sigma.translation_cm.y(), 0.0, 1e-12);
  EXPECT_NEAR(rep.sigma.translation_cm.z(), 2.0, 1e-12);
  // τ mean 12 ms, σ 2 ms.
  EXPECT_NEAR(rep.mean.time_offset_ms, 12.0, 1e-12);
  EXPECT_NEAR(rep.sigma.time_offset_ms, 2.0, 1e-12);
  // Errors: rotation 1, 1, 0 deg; x error -2, 0, +2 cm; τ error -1, 1, 3 ms.
  EXPECT_NEAR(rep.sequences[0].rotation_error_deg, 1.0, 1e-9);
  EXPECT_NEAR(rep.sequences[2].rotation_error_deg, 0.0, 1e-9);
  EXPECT_NEAR(rep.sequences[0].translation_error_cm.x(), -2.0, 1e-9);
  EXPECT_NEAR(rep.sequences[1].translation_error_cm.z(), 4.0, 1e-9);
  EXPECT_NEAR(rep.mean.rotation_error_deg, 2.0 / 3.0, 1e-9);
  EXPECT_NEAR(rep.mean.time_offset_error_ms, 1.0, 1e-9);
  EXPECT_NEAR(rep.sigma.time_offset_error_ms, 2.0, 1e-9);
}

TEST(Repeatability, RunWritesTableAndCsvAndFailsOnMissingResult) {
  testing::TempDir dir;
  for (const auto& [name, yaw] : {std::pair<std::string, double>{"seq1", 10.0}, {"seq2", 12.0}}) {
    std::filesystem::create_directory(dir.File(name));
    const SequenceResult s = Sequence(name, {180, 0, yaw}, {0.1, 0, 0.2}, 0.005);
    ASSERT_TRUE(WriteTextProto(dir.File(name + "/calibration.txtpb"), s.calibration).ok());
  }
  ReportPaths paths;
  paths.sequence_dirs = {dir.File("seq1"), dir.File("seq2/")};
  paths.out = dir.File("repeatability.txt");
  paths.out_csv = dir.File("repeatability.csv");
  std::ostringstream log;
  const Status status = report::Run(paths, DefaultReportParams(), &log);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::string table = log.str();
  std::string written;
  ASSERT_TRUE(ReadFileToString(dir.File("repeatability.txt"), &written).ok());
  EXPECT_EQ(written, table);
  EXPECT_NE(table.find("seq1"), std::string::npos) << table;
  EXPECT_NE(table.find("seq2"), std::string::npos) << table;
  EXPECT_EQ(table.find("rot err"), std::string::npos) << "no truth, no error columns";
  std::string csv;
  ASSERT_TRUE(ReadFileToString(dir.File("repeatability.csv"), &csv).ok());
  EXPECT_NE(csv.find("\nmean,10,0,20,180,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",11,"), std::string::npos) << csv;  // mean yaw 11 deg

  paths.sequence_dirs.push_back(dir.File("missing"));
  paths.out = dir.File("other.txt");
  const Status missing = report::Run(paths, DefaultReportParams(), nullptr);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("missing/calibration.txtpb"), std::string::npos);
  EXPECT_FALSE(testing::FileExists(dir.File("other.txt")));
}

// A calibration or truth file without an extrinsic, or with a NaN, would
// enter the mean and σ: an error naming the file and the field, no output.
TEST(Repeatability, EmptyOrNanCalibrationAndTruthAreRefused) {
  testing::TempDir dir;
  std::filesystem::create_directory(dir.File("seq1"));
  const SequenceResult good = Sequence("seq1", {180, 0, 10}, {0.1, 0, 0.2}, 0.005);
  ReportPaths paths;
  paths.sequence_dirs = {dir.File("seq1")};
  paths.out = dir.File("repeatability.txt");
  const std::string calibration = dir.File("seq1/calibration.txtpb");
  const std::string truth = dir.File("seq1/truth.txtpb");
  const std::pair<std::string, std::string> cases[] = {
      {"# no extrinsic\ntime_offset_s: 0.01\n", "imu_from_lidar.rotation is missing"},
      {"imu_from_lidar { rotation { w: nan } }\n", "imu_from_lidar.rotation is not finite"},
      {"imu_from_lidar { rotation { w: 1 } translation { x: nan } }\n",
       "imu_from_lidar.translation is not finite"},
      {"imu_from_lidar { rotation { w: 1 } }\ntime_offset_s: inf\n", "time_offset_s"},
  };
  for (const auto& [text, error] : cases) {
    ASSERT_TRUE(WriteFileAtomically(calibration, text).ok());
    Status status = report::Run(paths, DefaultReportParams(), nullptr);
    ASSERT_FALSE(status.ok()) << text;
    EXPECT_EQ(status.message().rfind(calibration + ": ", 0), 0u) << status.message();
    EXPECT_NE(status.message().find(error), std::string::npos) << status.message();
    EXPECT_FALSE(testing::FileExists(paths.out));
    // The same text as the truth, beside a good calibration.
    ASSERT_TRUE(WriteTextProto(calibration, good.calibration).ok());
    ASSERT_TRUE(WriteFileAtomically(truth, text).ok());
    status = report::Run(paths, DefaultReportParams(), nullptr);
    ASSERT_FALSE(status.ok()) << text;
    EXPECT_EQ(status.message().rfind(truth + ": ", 0), 0u) << status.message();
    EXPECT_FALSE(testing::FileExists(paths.out));
    std::filesystem::remove(truth);
  }
  ASSERT_TRUE(report::Run(paths, DefaultReportParams(), nullptr).ok());
}

// The verdict column, and a SUSPECT result the pipeline set aside
// (calibration.suspect.txtpb only): listed below the table, not in the mean.
TEST(Repeatability, VerdictColumnAndSuspectSequencesSetAside) {
  testing::TempDir dir;
  const std::pair<std::string, proto::CalibrationResult::Verdict> sequences[] = {
      {"ok", proto::CalibrationResult::OK}, {"weak", proto::CalibrationResult::WEAK}};
  for (const auto& [name, verdict] : sequences) {
    std::filesystem::create_directory(dir.File(name));
    SequenceResult s = Sequence(name, {180, 0, 10}, {0.1, 0, 0.2}, 0.005);
    s.calibration.set_verdict(verdict);
    ASSERT_TRUE(WriteTextProto(dir.File(name + "/calibration.txtpb"), s.calibration).ok());
  }
  std::filesystem::create_directory(dir.File("bad"));
  SequenceResult bad = Sequence("bad", {0, 0, 90}, {1, 1, 1}, 0.05);
  bad.calibration.set_verdict(proto::CalibrationResult::SUSPECT);
  ASSERT_TRUE(WriteTextProto(dir.File("bad/calibration.suspect.txtpb"), bad.calibration).ok());
  ReportPaths paths;
  paths.sequence_dirs = {dir.File("ok"), dir.File("weak"), dir.File("bad")};
  paths.out = dir.File("repeatability.txt");
  paths.out_csv = dir.File("repeatability.csv");
  std::ostringstream log;
  const Status status = report::Run(paths, DefaultReportParams(), &log);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::string table = log.str();
  EXPECT_NE(table.find("verdict"), std::string::npos) << table;
  EXPECT_NE(table.find("  OK\n"), std::string::npos) << table;
  EXPECT_NE(table.find("  WEAK\n"), std::string::npos) << table;
  EXPECT_NE(table.find("suspect, set aside (read its verdict_reasons): " +
                       dir.File("bad/calibration.suspect.txtpb")),
            std::string::npos)
      << table;
  std::string csv;
  ASSERT_TRUE(ReadFileToString(dir.File("repeatability.csv"), &csv).ok());
  EXPECT_NE(csv.find("time_offset_error_ms,verdict\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",,,,,,WEAK\n"), std::string::npos) << csv;
  // The mean is over the two usable results only (r (10, 0, 20) cm, yaw
  // 10 deg, tau 5 ms; the set-aside one has r (100, 100, 100) cm, tau 50 ms).
  const size_t mean = csv.find("\nmean,10,0,20,180,");
  ASSERT_NE(mean, std::string::npos) << csv;
  EXPECT_EQ(csv.substr(csv.find('\n', mean + 1) - 11, 11), ",10,5,,,,,,") << csv;

  paths.sequence_dirs = {dir.File("bad")};
  const Status none = report::Run(paths, DefaultReportParams(), nullptr);
  ASSERT_FALSE(none.ok());
  EXPECT_NE(none.message().find("no usable calibration"), std::string::npos) << none.message();
}

// The dataset's calibration: a "joint" row with its errors and verdict, and
// each sequence's consistency with it.
TEST(Repeatability, JointRowAndConsistencyColumn) {
  std::vector<SequenceResult> results = {Sequence("run1", {180, 0, 10}, {0.1, 0, 0.2}, 0.005),
                                         Sequence("run2", {180, 0, 12}, {0.1, 0, 0.2}, 0.005)};
  results[0].truth.emplace();
  *results[0].truth->mutable_imu_from_lidar() = Extrinsic({180, 0, 11}, {0.1, 0, 0.2});
  results[0].truth->set_time_offset_s(0.005);
  proto::CalibrationResult dataset;
  *dataset.mutable_imu_from_lidar() = Extrinsic({180, 0, 11.5}, {0.1, 0, 0.2});
  dataset.set_time_offset_s(0.005);
  dataset.set_verdict(proto::CalibrationResult::OK);
  proto::DatasetSequence* s1 = dataset.add_sequences();
  s1->set_name("run1");
  s1->set_used(true);
  s1->set_consistency_chi2(3.31);
  s1->set_consistency_limit(22.7);
  proto::DatasetSequence* s2 = dataset.add_sequences();
  s2->set_name("run2");
  s2->set_used(false);
  s2->set_consistency_chi2(412.0);
  s2->set_consistency_limit(22.7);
  Repeatability r = ComputeRepeatability(results, nullptr);
  AddDatasetCalibration(dataset, results, &r);
  ASSERT_TRUE(r.joint.has_value());
  EXPECT_TRUE(r.joint->has_errors);
  EXPECT_NEAR(r.joint->rotation_error_deg, 0.5, 1e-9);
  EXPECT_EQ(r.sequences[0].consistency, "chi2 3.3 / 22.7");
  EXPECT_EQ(r.sequences[1].consistency, "chi2 412.0 / 22.7 left out");
  const std::string table = FormatTable(r, "t");
  EXPECT_NE(table.find("consistency with the joint value"), std::string::npos) << table;
  EXPECT_NE(table.find("chi2 412.0 / 22.7 left out\n"), std::string::npos) << table;
  const size_t joint = table.find("\n     joint");
  ASSERT_NE(joint, std::string::npos) << table;
  EXPECT_NE(table.find("OK", joint), std::string::npos) << table;
}

}  // namespace
}  // namespace tiltcal::report
