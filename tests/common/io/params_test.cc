#include "common/io/params.h"

#include <gtest/gtest.h>

#include "common/io/atomic_file.h"
#include "common/io/text_proto.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/decode_params.pb.h"
#include "tiltcal/proto/ground_params.pb.h"

namespace tiltcal {
namespace {

Status LoadFromText(const std::string& text, google::protobuf::Message* params) {
  testing::TempDir dir;
  const std::string path = dir.File("params.txtpb");
  EXPECT_TRUE(WriteFileAtomically(path, text).ok());
  return LoadParams(path, params);
}

TEST(Params, ValidFileLoads) {
  proto::DecodeParams params;
  const Status status =
      LoadFromText("min_range_m: 0.5\nchunk_cache_size: 4\nmax_stamp_gap_s: 60\n", &params);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_DOUBLE_EQ(params.min_range_m(), 0.5);
}

TEST(Params, UnknownFieldIsAnErrorWithItsPosition) {
  proto::DecodeParams params;
  const Status status = LoadFromText("chunk_cache_size: 4\nmin_rang_m: 0.5\n", &params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("min_rang_m"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("line 2"), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("params.txtpb"), std::string::npos) << status.message();
}

TEST(Params, OutOfRangeValueNamesTheFieldAndTheBound) {
  proto::DecodeParams params;
  const Status status = LoadFromText("min_range_m: -1\nchunk_cache_size: 4\n", &params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("field min_range_m = -1 is below its minimum 0"),
            std::string::npos)
      << status.message();
}

TEST(Params, AboveMaximumAndZeroLeftByAForgottenField) {
  proto::DecodeParams params;
  Status status = LoadFromText("chunk_cache_size: 100\n", &params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("chunk_cache_size = 100 is above its maximum 64"),
            std::string::npos);
  status = LoadFromText("min_range_m: 0.1\n", &params);  // chunk_cache_size left 0
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("chunk_cache_size = 0 is below its minimum 1"),
            std::string::npos);
}

TEST(Params, RepeatedElementsAreCheckedWithTheirIndex) {
  proto::GroundParams params;
  ASSERT_TRUE(
      LoadParams(testing::SourceDir() + "/stages/ground/default_params.txtpb", &params).ok());
  ASSERT_GE(params.zone_model().rings_size(), 2);
  params.mutable_zone_model()->set_rings(1, 0);
  const Status status = ValidateAgainstSchema(params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("zone_model.rings[1] = 0"), std::string::npos)
      << status.message();
}

TEST(Params, NanIsRejected) {
  proto::DecodeParams params;
  const Status status = LoadFromText("min_range_m: nan\nchunk_cache_size: 4\n", &params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("not finite"), std::string::npos) << status.message();
}

// protobuf's parser alone refuses "x: 5  x: 0" but keeps 5 of "x: 0  x: 5"
// (a proto3 scalar at its default is not "present"): both are refused.
TEST(Params, AFieldGivenTwiceIsRefusedInEitherOrder) {
  for (const char* twice :
       {"min_range_m: 0\nmin_range_m: 0.5\n", "min_range_m: 0.5\nmin_range_m: 0\n",
        "min_range_m: 0\nmin_range_m: 0\n", "min_range_m: 0.5; min_range_m: 0.5\n"}) {
    proto::DecodeParams params;
    const Status status =
        LoadFromText(std::string("chunk_cache_size: 4\nmax_stamp_gap_s: 60\n") + twice, &params);
    ASSERT_FALSE(status.ok()) << twice;
    EXPECT_NE(status.message().find("params.txtpb: line "), std::string::npos) << status.message();
    EXPECT_NE(status.message().find("field min_range_m is given twice (first at line 3, column 1)"),
              std::string::npos)
        << status.message();
  }
}

TEST(Params, ANestedFieldOrMessageGivenTwiceIsRefusedWithItsPath) {
  const std::string defaults = testing::SourceDir() + "/stages/ground/default_params.txtpb";
  std::string text;
  ASSERT_TRUE(ReadFileToString(defaults, &text).ok());
  proto::GroundParams params;
  Status status = ParseTextProto(text, "ground.txtpb", &params);
  ASSERT_TRUE(status.ok()) << status.message();
  // A scalar at its default (0) then 1.5, inside a nested message.
  const std::string nested_scalar = "frame {\n  use_rig_up_direction: true\n  "
                                    "sensor_height_guess_m: 0.0\n  sensor_height_guess_m: 1.5\n}\n";
  std::string edited = text;
  const size_t frame = edited.find("frame {");
  ASSERT_NE(frame, std::string::npos);
  edited.replace(frame, edited.find("}", frame) + 2 - frame, nested_scalar);
  status = ParseTextProto(edited, "ground.txtpb", &params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("ground.txtpb: line "), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("field frame.sensor_height_guess_m is given twice"),
            std::string::npos)
      << status.message();
  // The whole nested message twice, the first one empty.
  status = ParseTextProto("frame {}\n" + text, "ground.txtpb", &params);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("field frame is given twice (first at line 1, column 1)"),
            std::string::npos)
      << status.message();
  // Repeated fields and lists may be given more than once.
  proto::GroundParams repeated;
  status = ParseTextProto("zone_model { rings: 2 rings: [4, 4] rings: 4 }", "ground.txtpb",
                          &repeated);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(repeated.zone_model().rings_size(), 4);
}

TEST(TextProto, WriteThenReadRoundTripsDoublesExactly) {
  testing::TempDir dir;
  proto::DecodeParams params;
  params.set_min_range_m(0.1 + 0.2);
  params.set_start_offset_s(1.0 / 3.0);
  ASSERT_TRUE(WriteTextProto(dir.File("p.txtpb"), params).ok());
  proto::DecodeParams back;
  ASSERT_TRUE(ReadTextProto(dir.File("p.txtpb"), &back).ok());
  EXPECT_EQ(back.min_range_m(), params.min_range_m());
  EXPECT_EQ(back.start_offset_s(), params.start_offset_s());
}

}  // namespace
}  // namespace tiltcal

namespace tiltcal {
namespace {

TEST(Params, MissingPathMeansTheDefaultText) {
  proto::DecodeParams params;
  const Status status =
      LoadParamsOrDefaults("", "min_range_m: 0.25\nchunk_cache_size: 4\nmax_stamp_gap_s: 60\n",
                           &params);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_DOUBLE_EQ(params.min_range_m(), 0.25);
  const Status bad =
      LoadParamsOrDefaults("", "min_range_m: -1\nchunk_cache_size: 4\nmax_stamp_gap_s: 60\n",
                           &params);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("default DecodeParams: field min_range_m = -1"),
            std::string::npos)
      << bad.message();
}

}  // namespace
}  // namespace tiltcal
