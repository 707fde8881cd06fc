// The keys of a rosbag2 metadata.yaml the readers use, from the layouts
// rosbag2 writes (block list) and hand-edited ones (flow list, quotes), with
// every other key ignored; the file itself read only when it is a regular
// file of at most kMaxRosbag2MetadataBytes.
#include "bag/ros2/rosbag2_metadata.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/testing/test_env.h"

namespace tiltcal::ros2 {
namespace {

TEST(Rosbag2Metadata, BlockListAsRosbag2WritesIt) {
  const Rosbag2Metadata m = ParseRosbag2Metadata(
      "rosbag2_bagfile_information:\n  version: 4\n  storage_identifier: sqlite3\n"
      "  relative_file_paths:\n    - talker_0.db3\n    - \"talker_1.db3\"\n"
      "  duration:\n    nanoseconds: 4531096768\n"
      "  topics_with_message_count:\n    - topic_metadata:\n        name: /topic\n"
      "  compression_format: \"\"\n  compression_mode: \"\"\n");
  EXPECT_EQ(m.relative_file_paths, (std::vector<std::string>{"talker_0.db3", "talker_1.db3"}));
  EXPECT_EQ(m.compression_format, "");
  EXPECT_EQ(m.storage_identifier, "sqlite3");
}

TEST(Rosbag2Metadata, QuotedStorageIdentifier) {
  EXPECT_EQ(ParseRosbag2Metadata("  storage_identifier: 'mcap'\n").storage_identifier, "mcap");
  EXPECT_EQ(ParseRosbag2Metadata("  storage_identifier: \"mcap\"\n").storage_identifier, "mcap");
}

TEST(Rosbag2Metadata, FileLargerThanTheLimitIsRefused) {
  testing::TempDir dir;
  const std::string file = dir.File("metadata.yaml");
  {
    std::ofstream out(file);
    out << "rosbag2_bagfile_information:\n  storage_identifier: sqlite3\n";
    out << std::string(kMaxRosbag2MetadataBytes, '#');
  }
  Rosbag2Metadata m;
  const Status status = ReadRosbag2Metadata(file, &m);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(file + ": "), std::string::npos) << status.message();
  EXPECT_NE(status.message().find("bytes a rosbag2 metadata.yaml can hold"), std::string::npos)
      << status.message();
}

TEST(Rosbag2Metadata, FlowListAndCompression) {
  const Rosbag2Metadata m = ParseRosbag2Metadata(
      "  relative_file_paths: [a_0.db3.zstd, 'a_1.db3.zstd']\r\n  compression_format: zstd\r\n");
  EXPECT_EQ(m.relative_file_paths, (std::vector<std::string>{"a_0.db3.zstd", "a_1.db3.zstd"}));
  EXPECT_EQ(m.compression_format, "zstd");
}

TEST(Rosbag2Metadata, NoKeysGiveNothing) {
  const Rosbag2Metadata m = ParseRosbag2Metadata("version: 4\n- x.db3\n");
  EXPECT_TRUE(m.relative_file_paths.empty());
  EXPECT_EQ(m.compression_format, "");
}

}  // namespace
}  // namespace tiltcal::ros2
