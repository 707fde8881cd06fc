#include "bag/mcap/mcap_reader.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "bag/mcap/chunk_decompressor.h"
#include "bag/ros1/messages.h"
#include "bag/ros2/cdr_reader.h"
#include "bag/ros2/messages.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/test_env.h"

namespace tiltcal::mcap {
namespace {

using testing::TempDir;

#define SKIP_WITHOUT_ORACLE()                                   \
  if (const std::string missing = testing::Ros2OracleMissing(); \
      !missing.empty()) {                                       \
    GTEST_SKIP() << missing;                                    \
  }

// compression, summary, big endian
class McapOracle : public ::testing::TestWithParam<std::tuple<const char*, bool, bool>> {};

TEST_P(McapOracle, EveryValueReadEqualsWhatTheLibraryWrote) {
  SKIP_WITHOUT_ORACLE();
  const auto [compression, summary, big_endian] = GetParam();
  TempDir dir;
  const std::string bag = dir.File("bag.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag,
                                    std::string("--format=mcap --compression=") + compression +
                                        (summary ? "" : " --no-summary") +
                                        (big_endian ? " --big-endian" : ""),
                                    dir.File("expected.txt"), &error))
      << error;
  McapReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.profile(), "ros2");
  EXPECT_EQ(reader.used_summary(), summary);
  EXPECT_EQ(reader.salvage_note(), "");  // complete either way: nothing salvaged
  EXPECT_EQ(reader.num_salvaged_messages(), 0);
  EXPECT_EQ(reader.TopicNames(),
            (std::vector<std::string>{"/chatter", "/hesai/pandar", "/imu", "/ouster/points",
                                      "/velodyne_points"}));
  EXPECT_EQ(reader.TopicType("/imu"), ros2::kImuType);
  EXPECT_EQ(reader.TopicType("/ouster/points"), ros2::kPointCloud2Type);
  EXPECT_EQ(reader.MessageCount("/imu"), 40);
  EXPECT_EQ(reader.TotalMessageCount(), 54);
  int count = 0;
  EXPECT_EQ(testing::CompareWithExpected(&reader, dir.File("expected.txt"), &count), "");
  EXPECT_EQ(count, 54);
}

INSTANTIATE_TEST_SUITE_P(
    Chunks, McapOracle,
    ::testing::Values(std::make_tuple("none", true, false), std::make_tuple("lz4", true, false),
                      std::make_tuple("zstd", true, false), std::make_tuple("zstd", false, false),
                      std::make_tuple("lz4", false, true), std::make_tuple("none", false, false)));

// A ROS 1 bag converted to MCAP: profile "ros1", schemas "ros1msg", messages
// "ros1", written by @mcap/core with @foxglove/rosmsg-serialization.
TEST(McapReader, Ros1EncodedMessagesReadEqualToWhatTheLibraryWrote) {
  SKIP_WITHOUT_ORACLE();
  for (const char* summary : {"", " --no-summary"}) {
    TempDir dir;
    const std::string bag = dir.File("bag.mcap");
    std::string error;
    ASSERT_TRUE(testing::WriteRos2Bag(
        bag, std::string("--format=mcap --encoding=ros1 --compression=zstd") + summary,
        dir.File("expected.txt"), &error))
        << error;
    McapReader reader;
    const Status status = reader.Open(bag);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(reader.profile(), "ros1");
    EXPECT_EQ(reader.salvage_note(), "");
    EXPECT_EQ(reader.num_salvaged_messages(), 0);
    EXPECT_EQ(reader.TopicType("/imu"), ros1::kImuType);
    EXPECT_EQ(reader.TopicType("/velodyne_points"), ros1::kPointCloud2Type);
    EXPECT_EQ(reader.TopicType("/chatter"), "std_msgs/String");
    int count = 0;
    EXPECT_EQ(testing::CompareWithExpected(&reader, dir.File("expected.txt"), &count), "")
        << summary;
    EXPECT_EQ(count, 54);
  }
}

TEST(McapReader, TruncatedRecordingIsSalvagedWithANote) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=mcap --compression=zstd", "", &error)) << error;
  std::filesystem::resize_file(bag, std::filesystem::file_size(bag) * 6 / 10);
  McapReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_FALSE(reader.indexed());
  EXPECT_NE(reader.salvage_note().find("ends inside the Chunk record"), std::string::npos)
      << reader.salvage_note();
  EXPECT_GT(reader.num_salvaged_messages(), 0);
  EXPECT_LT(reader.TotalMessageCount(), 54);
  int64_t read = 0;
  int64_t last = INT64_MIN;
  ASSERT_TRUE(reader
                  .ReadMessages({},
                                [&](const bag::Message& m) {
                                  EXPECT_GE(m.time_ns, last);
                                  last = m.time_ns;
                                  ++read;
                                  return Status::Ok();
                                })
                  .ok());
  EXPECT_EQ(read, reader.TotalMessageCount());
}

TEST(McapReader, CorruptedChunkIsAnErrorNamingFileAndChunk) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=mcap --compression=none", "", &error)) << error;
  {
    std::fstream f(bag, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(6000);  // inside the first chunk's point-cloud data
    char c = 0;
    f.read(&c, 1);
    f.seekp(6000);
    c = static_cast<char>(c ^ 0x5A);
    f.write(&c, 1);
  }
  McapReader reader;
  Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();  // the summary is intact
  status = reader.ReadMessages({}, [](const bag::Message&) { return Status::Ok(); });
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(bag + ": byte "), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("CRC mismatch"), std::string::npos) << status.message();
}

TEST(McapReader, WrongMagicIsAnError) {
  TempDir dir;
  std::ofstream(dir.File("x.mcap")) << "#ROSBAG V2.0\n" << std::string(100, '\0');
  McapReader reader;
  const Status status = reader.Open(dir.File("x.mcap"));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(dir.File("x.mcap") + ": byte 0: not an MCAP file"),
            std::string::npos)
      << status.message();
}

TEST(McapChunkDecompressor, UnknownCompressionIsAnError) {
  ChunkRecord chunk;
  chunk.compression = "brotli";
  std::vector<uint8_t> out;
  ChunkDecompressor decompressor;
  const Status status = decompressor.Decompress(chunk, &out);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("unknown chunk compression 'brotli'"), std::string::npos);
}

TEST(McapReader, ReadsTheTalkerFixture) {
  const std::string fixtures = testing::SharedFixturesDir();
  if (fixtures.empty()) GTEST_SKIP() << "no ../shared/fixtures";
  const std::string bag = fixtures + "/bags/ros2/mcap_talker/talker.mcap";
  if (!testing::FileExists(bag)) GTEST_SKIP() << "no " << bag;
  McapReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(reader.used_summary());
  EXPECT_EQ(reader.TopicType("/topic"), "std_msgs/msg/String");
  EXPECT_EQ(reader.MessageCount("/topic"), 10);   // metadata.yaml
  EXPECT_EQ(reader.MessageCount("/rosout"), 10);  // metadata.yaml
  int64_t start = 0, end = 0;
  ASSERT_TRUE(reader.TimeRange(&start, &end));
  EXPECT_EQ(start, 1585866235112411371LL);  // metadata.yaml: starting_time
  EXPECT_EQ(end - start, 4531096768LL);     // metadata.yaml: duration
  std::vector<std::string> texts;
  ASSERT_TRUE(reader
                  .ReadMessages({{"/topic"}},
                                [&](const bag::Message& m) {
                                  ros2::CdrReader r;
                                  std::string text;
                                  TILTCAL_RETURN_IF_ERROR(r.Open(m.data, m.size));
                                  TILTCAL_RETURN_IF_ERROR(r.String("data", &text));
                                  texts.push_back(text);
                                  return Status::Ok();
                                })
                  .ok());
  ASSERT_EQ(texts.size(), 10u);
  EXPECT_EQ(texts.front(), "Hello, world! 0");
  EXPECT_EQ(texts.back(), "Hello, world! 9");
  EXPECT_GT(reader.chunks_decompressed(), 0u);  // zstd chunks
}

}  // namespace
}  // namespace tiltcal::mcap
