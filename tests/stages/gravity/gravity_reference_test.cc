#include "stages/gravity/gravity_reference.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "common/geometry/angles.h"
#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"
#include "stages/gravity/default_params_text.h"
#include "tests/testing/params_text.h"
#include "tests/testing/test_env.h"

namespace tiltcal::gravity {
namespace {

using geometry::AngleBetweenDeg;
using geometry::kDegPerRad;

proto::GravityParams Params(const std::string& overrides = "") {
  return testing::DefaultParamsWith<proto::GravityParams>(DefaultParamsText(), overrides);
}

// A level calibration that started still, with g_a = R(a, angle) g0, a the
// unit vector of `axis` perpendicular to g0 (so g_a is `angle` from g0).
FlatCalibration Level(const std::string& path, const Eigen::Vector3d& axis, double angle_deg,
                      double norm_mps2 = 9.81) {
  const Eigen::Vector3d g0 = Eigen::Vector3d(0.05, -0.02, -1.0).normalized();
  const Eigen::Vector3d a = (axis - axis.dot(g0) * g0).normalized();
  FlatCalibration c;
  c.path = path;
  *c.result.mutable_gravity_in_world() =
      ToProto(Eigen::AngleAxisd(angle_deg / kDegPerRad, a) * g0 * norm_mps2);
  c.result.set_static_start(true);
  c.result.add_ground_residuals_used("flat");
  c.result.add_ground_residuals_used("dist");
  c.result.set_verdict(proto::CalibrationResult::WEAK);
  return c;
}

TEST(GravityReference, MeanDirectionWithMeanNormAndTheLargestAngle) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  const std::vector<FlatCalibration> calibrations = {
      Level("a", x, 0.05, 9.80), Level("b", x, -0.05, 9.82), Level("c", Eigen::Vector3d::UnitY(), 0.0)};
  proto::GravityReference out;
  ASSERT_TRUE(CombineFlatCalibrations(calibrations, Params().flat_calibrations(), &out).ok());
  ASSERT_TRUE(out.has_gravity_flat());
  const Eigen::Vector3d g_f = ToEigen(out.gravity_flat_in_imu());
  // ±0.05 deg about x cancel: the mean direction is g0's.
  EXPECT_LT(AngleBetweenDeg(g_f, Eigen::Vector3d(0.05, -0.02, -1.0)), 1e-9);
  EXPECT_NEAR(g_f.norm(), 9.81, 1e-12);
  ASSERT_EQ(out.flat_calibrations_size(), 3);
  EXPECT_NEAR(out.flat_calibrations(0).angle_from_combined_deg(), 0.05, 1e-9);
  EXPECT_NEAR(out.flat_calibrations(2).angle_from_combined_deg(), 0.0, 1e-9);
  EXPECT_NEAR(out.flat_calibrations_max_angle_deg(), 0.05, 1e-9);
  EXPECT_EQ(out.gravity_flat_source(), "flat calibrations (3 of 3)");
}

TEST(GravityReference, UnusableCalibrationsAreLeftOutAndNamed) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  std::vector<FlatCalibration> calibrations = {Level("good", x, 0.0), Level("moving", x, 3.0),
                                               Level("tilted", x, 8.0), Level("suspect", x, 5.0)};
  calibrations[1].result.set_static_start(false);
  calibrations[2].result.clear_ground_residuals_used();
  calibrations[3].result.set_verdict(proto::CalibrationResult::SUSPECT);
  proto::GravityReference out;
  ASSERT_TRUE(CombineFlatCalibrations(calibrations, Params().flat_calibrations(), &out).ok());
  EXPECT_LT(AngleBetweenDeg(ToEigen(out.gravity_flat_in_imu()),
                            ToEigen(calibrations[0].result.gravity_in_world())),
            1e-9);
  EXPECT_EQ(out.gravity_flat_source(), "flat calibrations (1 of 4)");
  EXPECT_TRUE(out.flat_calibrations(0).used());
  EXPECT_NE(out.flat_calibrations(1).reason().find("did not start still"), std::string::npos);
  EXPECT_NE(out.flat_calibrations(2).reason().find("not level"), std::string::npos);
  EXPECT_EQ(out.flat_calibrations(3).reason(), "verdict SUSPECT");

  // With use_suspect the SUSPECT one counts, and is 2.5 deg from the mean.
  proto::GravityReference with_suspect;
  const Status status = CombineFlatCalibrations(
      calibrations, Params("flat_calibrations { use_suspect: true }").flat_calibrations(),
      &with_suspect);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("suspect: 2.500 deg"), std::string::npos) << status.message();
}

TEST(GravityReference, DisagreeingCalibrationsAreAnErrorNamingEach) {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  proto::GravityReference out;
  const Status status = CombineFlatCalibrations(
      {Level("run_1", x, 0.0), Level("run_2", x, 0.05), Level("run_3", x, -0.05),
       Level("run_4", x, 0.02), Level("run_5", x, 1.0)},
      Params().flat_calibrations(), &out);
  ASSERT_FALSE(status.ok());
  // The mean lies at about 0.204 deg: only run_5 (0.796 deg) is beyond 0.3.
  EXPECT_NE(status.message().find("run_5: 0.79"), std::string::npos) << status.message();
  EXPECT_EQ(status.message().find("run_1:"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("max_angle_from_combined_deg"), std::string::npos);

  proto::GravityReference none;
  const Status empty = CombineFlatCalibrations({}, Params().flat_calibrations(), &none);
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.message().find("no flat-ground calibration"), std::string::npos);
}

TEST(GravityReference, RigNamesAFlatDatasetFolderOrAFile) {
  testing::TempDir dir;
  std::filesystem::create_directories(dir.File("husky_flat/out"));
  std::filesystem::create_directories(dir.File("husky_tilted"));
  const std::string rig = dir.File("husky_tilted/rig.txtpb");
  EXPECT_EQ(ResolveGravityReferencePath(rig, "../husky_flat"),
            dir.File("husky_tilted/../husky_flat/out/gravity_reference.txtpb"));
  EXPECT_EQ(ResolveGravityReferencePath(rig, "../husky_flat/out/run1/gravity.txtpb"),
            dir.File("husky_tilted/../husky_flat/out/run1/gravity.txtpb"));
}

// Through the executable: the reference file, and exit 1 with one line when
// no calibration is usable.
TEST(GravityReference, ToolWritesTheReferenceOrFailsWithOneLine) {
  testing::TempDir dir;
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  FlatCalibration a = Level("a", x, 0.02), b = Level("b", x, -0.02);
  ASSERT_TRUE(WriteTextProto(dir.File("a.txtpb"), a.result).ok());
  ASSERT_TRUE(WriteTextProto(dir.File("b.txtpb"), b.result).ok());
  const std::string tool = testing::ToolPath("tiltcal_gravity_reference");
  std::string output;
  ASSERT_EQ(testing::RunCommand(tool + " --out=" + dir.File("ref.txtpb") + " " +
                                    dir.File("a.txtpb") + " " + dir.File("b.txtpb"),
                                &output),
            0)
      << output;
  proto::GravityReference ref;
  ASSERT_TRUE(ReadTextProto(dir.File("ref.txtpb"), &ref).ok());
  EXPECT_TRUE(ref.has_gravity_flat());
  EXPECT_EQ(ref.provenance().producer(), "tiltcal_gravity_reference");
  EXPECT_NE(output.find("tiltcal_gravity_reference: g_f = "), std::string::npos) << output;

  b.result.set_static_start(false);
  a.result.set_static_start(false);
  ASSERT_TRUE(WriteTextProto(dir.File("a.txtpb"), a.result).ok());
  ASSERT_TRUE(WriteTextProto(dir.File("b.txtpb"), b.result).ok());
  EXPECT_EQ(testing::RunCommand(tool + " --out=" + dir.File("ref2.txtpb") + " " +
                                    dir.File("a.txtpb") + " " + dir.File("b.txtpb"),
                                &output),
            1);
  EXPECT_NE(output.find("no flat-ground calibration gives g_f"), std::string::npos) << output;
  EXPECT_FALSE(testing::FileExists(dir.File("ref2.txtpb")));
}

// g_a that are no gravity, or that cannot share one: exit 1 with one error
// line naming the files and their values, no output.
TEST(GravityReference, ToolRefusesOppositeNonFiniteAndWrongNormGravities) {
  struct Case {
    const char* what;
    Eigen::Vector3d g_a, g_b;
    std::vector<std::string> said;  // parts of the error line
  };
  const double nan = std::nan("");
  const std::vector<Case> cases = {
      {"opposite", {0, 0, 9.81}, {0, 0, -9.81},
       {"disagree about gravity", "180.000 deg", "a.txtpb g_a (0, 0, 9.81)",
        "b.txtpb g_a (0, 0, -9.81)", "max_angle_from_combined_deg"}},
      {"90 deg apart", {0, 0, 9.81}, {9.81, 0, 0},
       {"disagree about gravity", "a.txtpb: 45.000 deg (g_a (0, 0, 9.81))",
        "b.txtpb: 45.000 deg (g_a (9.81, 0, 0))"}},
      {"1e300", {0, 0, 9.81}, {0, 0, 1e300}, {"b.txtpb: gravity_in_world (0, 0, 1e+300) has norm"}},
      {"norm 1.5", {0, 0, 9.81}, {0, 0, 1.5},
       {"b.txtpb: gravity_in_world (0, 0, 1.5) has norm 1.5 m/s^2, outside "
        "flat_calibrations.min_gravity_norm_mps2 9.7 to max_gravity_norm_mps2 9.9"}},
      {"norm 9.6", {0, 0, 9.6}, {0, 0, 9.81},
       {"a.txtpb: gravity_in_world (0, 0, 9.6) has norm 9.6"}},
      {"nan", {0, 0, 9.81}, {nan, 0, 9.81},
       {"b.txtpb: gravity_in_world (nan, 0, 9.81) is not finite"}},
  };
  const std::string tool = testing::ToolPath("tiltcal_gravity_reference");
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    testing::TempDir dir;
    FlatCalibration a = Level("a", Eigen::Vector3d::UnitX(), 0.0);
    FlatCalibration b = a;
    *a.result.mutable_gravity_in_world() = ToProto(c.g_a);
    *b.result.mutable_gravity_in_world() = ToProto(c.g_b);
    ASSERT_TRUE(WriteTextProto(dir.File("a.txtpb"), a.result).ok());
    ASSERT_TRUE(WriteTextProto(dir.File("b.txtpb"), b.result).ok());
    std::string output;
    EXPECT_EQ(testing::RunCommand(tool + " --out=" + dir.File("ref.txtpb") + " " +
                                      dir.File("a.txtpb") + " " + dir.File("b.txtpb"),
                                  &output),
              1)
        << output;
    EXPECT_FALSE(testing::FileExists(dir.File("ref.txtpb")));
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    for (const std::string& part : c.said) {
      EXPECT_NE(output.find(part), std::string::npos) << part << " in " << output;
    }
  }
}

TEST(GravityReference, NormBoundsAreValidated) {
  proto::GravityReference out;
  const Status status = CombineFlatCalibrations(
      {Level("a", Eigen::Vector3d::UnitX(), 0.0)},
      Params("flat_calibrations { min_gravity_norm_mps2: 9.9 max_gravity_norm_mps2: 9.7 }")
          .flat_calibrations(),
      &out);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("min_gravity_norm_mps2 = 9.9 is not below"), std::string::npos)
      << status.message();
}

}  // namespace
}  // namespace tiltcal::gravity
