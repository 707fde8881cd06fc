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
