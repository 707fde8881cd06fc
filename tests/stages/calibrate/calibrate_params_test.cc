// The calibrator's params: the default file sets every field (no component
// runs on a value the file does not show), and each cross-field rule rejects
// its violation with an error naming the field.

#include <cmath>
#include <string>
#include <utility>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/params.h"
#include "stages/calibrate/calibrate.h"
#include "stages/calibrate/calibrate_params_validation.h"
#include "stages/calibrate/default_params_text.h"
#include "stages/calibrate/problem/bias_segments.h"
#include "tests/stages/calibrate/calibrate_params_text.h"
#include "tests/testing/test_env.h"

namespace tiltcal::calibrate {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::TextFormat;

// Appends to *missing the dotted path of every field of `descriptor`
// (recursively) that the text behind `tree` does not set.
void CollectUnsetFields(const Descriptor* descriptor, const TextFormat::ParseInfoTree* tree,
                        const std::string& prefix, std::string* missing) {
  for (int i = 0; i < descriptor->field_count(); ++i) {
    const FieldDescriptor* field = descriptor->field(i);
    const std::string path = prefix + field->name();
    if (tree->GetLocation(field, -1).line < 0) {
      *missing += path + " ";
      continue;
    }
    if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      CollectUnsetFields(field->message_type(), tree->GetTreeForNested(field, -1), path + ".",
                         missing);
    }
  }
}

TEST(CalibrateParamsTest, DefaultParamsFileSetsEveryField) {
  proto::CalibrateParams params;
  TextFormat::ParseInfoTree tree;
  TextFormat::Parser parser;
  parser.WriteLocationsTo(&tree);
  ASSERT_TRUE(parser.ParseFromString(std::string(DefaultParamsText()), &params));
  std::string missing;
  CollectUnsetFields(proto::CalibrateParams::descriptor(), &tree, "", &missing);
  EXPECT_EQ(missing, "") << "fields the default params file does not set";
  EXPECT_TRUE(ValidateCalibrateParams(params).ok());
}

TEST(CalibrateParamsTest, LoadingChecksTheRulesAndNamesTheFile) {
  proto::CalibrateParams params;
  ASSERT_TRUE(LoadCalibrateParams("", &params).ok());  // the embedded defaults
  EXPECT_DOUBLE_EQ(params.map().voxel_m(), 1.0);
  tiltcal::testing::TempDir dir;
  std::string text(DefaultParamsText());
  const std::string min_range = "min_range_m: 1.0";
  ASSERT_NE(text.find(min_range), std::string::npos);
  text.replace(text.find(min_range), min_range.size(), "min_range_m: 90");  // > max_range_m (80)
  ASSERT_TRUE(WriteFileAtomically(dir.File("p.txtpb"), text).ok());
  const Status status = LoadCalibrateParams(dir.File("p.txtpb"), &params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("p.txtpb"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("scans.max_range_m"), std::string::npos) << status.message();
}

// A user's params file from before the clock drift (no time_offset_drift
// block) keeps working: the block's defaults are used.
TEST(CalibrateParamsTest, ParamsWithoutTheClockDriftBlockGetItsDefaults) {
  std::string text(DefaultParamsText());
  const size_t begin = text.find("time_offset_drift {");
  ASSERT_NE(begin, std::string::npos);
  const size_t end = text.find('}', begin);
  text.erase(begin, end + 1 - begin);
  tiltcal::testing::TempDir dir;
  ASSERT_TRUE(WriteFileAtomically(dir.File("old.txtpb"), text).ok());
  proto::CalibrateParams params;
  const Status status = LoadCalibrateParams(dir.File("old.txtpb"), &params);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_TRUE(params.has_time_offset_drift());
  EXPECT_EQ(params.time_offset_drift().mode(), proto::TimeOffsetDriftParams::AUTO);
  EXPECT_DOUBLE_EQ(params.time_offset_drift().expected_rate_ppm(), 5.0);
  EXPECT_DOUBLE_EQ(params.time_offset_drift().max_rate_ppm(), 2000.0);
}

// A params file written before observability.variance_factors existed gets
// the per-type variance components, as the defaults do.
TEST(CalibrateParamsTest, ParamsWithoutVarianceFactorsGetThePerTypeComponents) {
  std::string text(DefaultParamsText());
  const size_t at = text.find("variance_factors: PER_TYPE");
  ASSERT_NE(at, std::string::npos);
  text.erase(at, std::string("variance_factors: PER_TYPE").size());
  tiltcal::testing::TempDir dir;
  ASSERT_TRUE(WriteFileAtomically(dir.File("old.txtpb"), text).ok());
  proto::CalibrateParams params;
  const Status status = LoadCalibrateParams(dir.File("old.txtpb"), &params);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(params.observability().variance_factors(), proto::ObservabilityParams::PER_TYPE);
}

// The error of ValidateCalibrateParams on the defaults with `override_text`.
std::string ErrorWith(const std::string& override_text) {
  proto::CalibrateParams params = tiltcal::testing::DefaultCalibrateParamsWith();
  EXPECT_TRUE(TextFormat::MergeFromString(override_text, &params)) << override_text;
  const Status status = ValidateCalibrateParams(params);
  EXPECT_FALSE(status.ok()) << override_text;
  return status.message();
}

TEST(CalibrateParamsTest, EachRuleNamesItsField) {
  const std::pair<const char*, const char*> cases[] = {
      {"imu_noise { gyro_sigma_radps: 0 }", "imu_noise.gyro_sigma_radps"},
      {"imu_noise { accel_sigma_mps2: 0 }", "imu_noise.accel_sigma_mps2"},
      {"imu_noise { gyro_bias_segment_s: 1e-300 }", "imu_noise.gyro_bias_segment_s = 1e-300"},
      {"imu_noise { accel_bias_segment_s: 0.5 }", "imu_noise.accel_bias_segment_s = 0.5"},
      {"scans { min_range_m: 5 max_range_m: 5 }", "scans.max_range_m"},
      {"lidar { sigma_m: 0 }", "lidar.sigma_m"},
      {"init { odometry_position_sigma_m: 0 }", "init.odometry_position_sigma_m"},
      {"init { deskew_node_spacing_s: 0 }", "init.deskew_node_spacing_s"},
      {"odometry { quality_map { voxel_m: 0 } }", "odometry.quality_map.voxel_m"},
      {"odometry { method: VOXEL_ICP voxel_icp { max_correspondence_m: 0 } }",
       "odometry.voxel_icp.max_correspondence_m"},
      {"odometry { method: VOXEL_ICP voxel_icp { kernel_scale_m: 0 } }",
       "odometry.voxel_icp.kernel_scale_m"},
      {"odometry { method: VOXEL_ICP voxel_icp { max_plane_thickness_m: 0 } }",
       "odometry.voxel_icp.max_plane_thickness_m"},
      {"odometry { method: VOXEL_ICP voxel_icp { min_plane_points: 30 max_points_per_cell: 20 } }",
       "odometry.voxel_icp.min_plane_points"},
      {"map { voxel_m: 0 }", "map.voxel_m"},
      {"association { max_distance_m: 0 }", "association.max_distance_m"},
      {"association { deskew_node_spacing_s: 0 }", "association.deskew_node_spacing_s"},
      {"ground { flat { sigma: 0 } }", "ground.flat.sigma"},
      {"ground { dist { sigma: 0 } }", "ground.dist.sigma"},
      {"ground { incl { sigma: 0 } }", "ground.incl.sigma"},
      {"ground { up { sigma: 0 } }", "ground.up.sigma"},
      {"verdict { max_gyro_rms: 0 }", "verdict.max_gyro_rms"},
      {"verdict { max_accel_rms: 0 }", "verdict.max_accel_rms"},
      {"verdict { max_lidar_rms: 0 }", "verdict.max_lidar_rms"},
      {"verdict { max_ground_rms: 0 }", "verdict.max_ground_rms"},
      {"verdict { large_rotation_deg: 0 }", "verdict.large_rotation_deg"},
      {"verdict { large_translation_m: 0 }", "verdict.large_translation_m"},
  };
  for (const auto& [override_text, field] : cases) {
    const std::string message = ErrorWith(override_text);
    EXPECT_NE(message.find(field), std::string::npos) << override_text << ": " << message;
  }
}

// One IMU stamp far in the future (2^32 − 1 s) would make the knot grid and
// the static detection span 136 years: refused before any knot is made.
TEST(CalibrateParamsTest, ImuSpanBeyondMaxDurationIsRefused) {
  CalibrateInputs inputs;
  inputs.imu.resize(20);
  for (size_t i = 0; i < inputs.imu.size(); ++i) inputs.imu[i].time_s = 0.005 * i;
  inputs.imu.back().time_s = 4294967295.0;
  proto::CalibrationResult result;
  const Status status = Calibrate(inputs, tiltcal::testing::DefaultCalibrateParamsWith(), &result,
                                  nullptr, nullptr);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("more than spline.max_duration_s = 3600 s"), std::string::npos)
      << status.message();
}

TEST(CalibrateParamsTest, BiasSegmentsBeyondTheirCountAreAnErrorNotACrash) {
  BiasSegments bias;
  const Status too_many = bias.Split(0.0, 4294967295.0, 1.0, "imu_noise.gyro_bias_segment_s");
  ASSERT_FALSE(too_many.ok());
  EXPECT_NE(too_many.message().find("imu_noise.gyro_bias_segment_s = 1 s"), std::string::npos)
      << too_many.message();
  EXPECT_EQ(bias.size(), 1);  // left as it was
  EXPECT_FALSE(bias.Split(0.0, 1e300, 1e-300, "f").ok());  // the count overflows an int
  ASSERT_TRUE(bias.Split(0.0, 60.0, 10.0, "f").ok());
  EXPECT_EQ(bias.size(), 6);
  EXPECT_EQ(bias.Index(std::nan("")), 0);
}

TEST(CalibrateParamsTest, VoxelIcpNeedsItsSettingsOnlyWhenChosen) {
  proto::CalibrateParams params = tiltcal::testing::DefaultCalibrateParamsWith();
  params.mutable_odometry()->clear_voxel_icp();
  params.mutable_odometry()->set_method(proto::LidarOdometryParams::VOXEL_ICP);
  const Status status = ValidateCalibrateParams(params);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            "params: odometry.voxel_icp is required with odometry.method VOXEL_ICP");
  // A params file written for GICP (before VOXEL_ICP existed) stays valid.
  params.mutable_odometry()->set_method(proto::LidarOdometryParams::GICP);
  EXPECT_TRUE(ValidateCalibrateParams(params).ok());
  EXPECT_TRUE(ValidateAgainstSchema(params).ok());
}

TEST(CalibrateParamsTest, GroundCorrelationNeedsEnoughBatchesOrNone) {
  proto::CalibrateParams params = tiltcal::testing::DefaultCalibrateParamsWith();
  EXPECT_EQ(params.observability().correlation_batches(), 20);
  params.mutable_observability()->set_correlation_batches(3);
  const Status status = ValidateCalibrateParams(params);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            "params: observability.correlation_batches = 3 must be 0 or at least 4");
  params.mutable_observability()->set_correlation_batches(0);
  EXPECT_TRUE(ValidateCalibrateParams(params).ok());
  params.mutable_observability()->set_correlation_batches(4);
  EXPECT_TRUE(ValidateCalibrateParams(params).ok());
}

}  // namespace
}  // namespace tiltcal::calibrate
