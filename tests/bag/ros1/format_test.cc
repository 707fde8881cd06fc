#include "bag/ros1/format.h"

#include <gtest/gtest.h>

#include "tests/bag/ros1/bag_test_util.h"
#include "tests/testing/test_env.h"

namespace tiltcal::ros1 {
namespace {

TEST(Ros1Format, HeaderBuildThenParseRoundTrips) {
  HeaderFields fields;
  fields["op"] = OpValue(Op::kChunk);
  fields["size"] = U32Value(123456);
  fields["index_pos"] = U64Value(0x0102030405060708ULL);
  fields["time"] = TimeValue(RosTime{1700000000, 999999999});
  fields["compression"] = "lz4";
  fields["weird"] = "a=b=c";  // values may contain '='
  const std::string header = BuildHeader(fields);

  RecordHeader parsed;
  ASSERT_TRUE(parsed.Parse(header.data(), header.size()).ok());
  ASSERT_EQ(parsed.fields().size(), fields.size());
  // Fields come out in std::map order, the order ros_comm writes them.
  EXPECT_EQ(parsed.fields()[0].first, "compression");
  uint8_t op = 0;
  ASSERT_TRUE(parsed.GetOp(&op).ok());
  EXPECT_EQ(op, 0x05);
  uint32_t size = 0;
  ASSERT_TRUE(parsed.GetU32("size", &size).ok());
  EXPECT_EQ(size, 123456u);
  uint64_t index_pos = 0;
  ASSERT_TRUE(parsed.GetU64("index_pos", &index_pos).ok());
  EXPECT_EQ(index_pos, 0x0102030405060708ULL);
  RosTime t;
  ASSERT_TRUE(parsed.GetTime("time", &t).ok());
  EXPECT_EQ(t.sec, 1700000000u);
  EXPECT_EQ(t.nsec, 999999999u);
  std::string s;
  ASSERT_TRUE(parsed.GetString("weird", &s).ok());
  EXPECT_EQ(s, "a=b=c");
  EXPECT_FALSE(parsed.Has("absent"));
}

TEST(Ros1Format, HeaderBytesAreLengthPrefixedNameEqualsValue) {
  const std::string header = BuildHeader({{"op", OpValue(Op::kMessageData)}});
  EXPECT_EQ(header, std::string("\x04\x00\x00\x00op=\x02", 8));
  std::string record;
  AppendRecord(&record, {{"op", OpValue(Op::kMessageData)}}, "xyz");
  EXPECT_EQ(record, std::string("\x08\x00\x00\x00", 4) + header +
                        std::string("\x03\x00\x00\x00xyz", 7));
}

TEST(Ros1Format, ParseErrors) {
  RecordHeader h;
  const std::string no_equals("\x03\x00\x00\x00opx", 7);
  Status status = h.Parse(no_equals.data(), no_equals.size());
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("no '='"), std::string::npos) << status.message();

  const std::string too_long("\x09\x00\x00\x00op=\x02", 8);
  status = h.Parse(too_long.data(), too_long.size());
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("past the header"), std::string::npos) << status.message();

  const std::string short_len("\x04\x00", 2);
  EXPECT_FALSE(h.Parse(short_len.data(), short_len.size()).ok());

  const std::string header = BuildHeader({{"conn", "abc"}});
  ASSERT_TRUE(h.Parse(header.data(), header.size()).ok());
  uint32_t conn = 0;
  status = h.GetU32("conn", &conn);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("'conn' has 3 bytes, expected 4"), std::string::npos);
  uint64_t index_pos = 0;
  status = h.GetU64("index_pos", &index_pos);
  EXPECT_NE(status.message().find("no field 'index_pos'"), std::string::npos);
}

TEST(Ros1Format, TimeConversions) {
  EXPECT_EQ(RosTimeToNs(RosTime{1, 2}), 1000000002);
  EXPECT_EQ(RosTimeToNs(RosTime{4294967295u, 999999999u}), 4294967295999999999LL);
  RosTime t;
  ASSERT_TRUE(NsToRosTime(1700000000123456789LL, &t));
  EXPECT_EQ(t.sec, 1700000000u);
  EXPECT_EQ(t.nsec, 123456789u);
  EXPECT_FALSE(NsToRosTime(-1, &t));
  EXPECT_FALSE(NsToRosTime(4294967296LL * 1000000000, &t));
  std::string bytes;
  AppendRosTime(&bytes, RosTime{7, 8});
  EXPECT_EQ(bytes, std::string("\x07\x00\x00\x00\x08\x00\x00\x00", 8));
  EXPECT_EQ(RosTimeToNs(LoadRosTime(bytes.data())), 7000000008);
}

// The bag header of a real bag parses, and rebuilding it gives its bytes.
TEST(Ros1Format, RealBagHeaderRoundTrips) {
  const std::string dir = testing::SharedFixturesDir();
  if (dir.empty()) GTEST_SKIP() << "../shared/fixtures absent";
  const std::string bytes =
      testing::ReadFileOrEmpty(dir + "/bags/ros1/rosbagjs_no-messages.bag");
  ASSERT_EQ(bytes.substr(0, kVersionLine.size()), kVersionLine);
  const size_t pos = kVersionLine.size();
  const uint32_t header_len = LoadU32Le(bytes.data() + pos);
  const uint32_t data_len = LoadU32Le(bytes.data() + pos + 4 + header_len);
  EXPECT_EQ(header_len + data_len, kBagHeaderPaddedSize);
  RecordHeader h;
  ASSERT_TRUE(h.Parse(bytes.data() + pos + 4, header_len).ok());
  uint64_t index_pos = 0;
  ASSERT_TRUE(h.GetU64("index_pos", &index_pos).ok());
  EXPECT_EQ(index_pos, bytes.size());
  HeaderFields fields;
  for (const auto& [name, value] : h.fields()) fields[std::string(name)] = std::string(value);
  EXPECT_EQ(BuildHeader(fields), bytes.substr(pos + 4, header_len));
}

}  // namespace
}  // namespace tiltcal::ros1
