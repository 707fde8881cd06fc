#include "bag/ros2/sqlite_bag_reader.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros2/cdr_reader.h"
#include "bag/ros2/messages.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/test_env.h"

namespace tiltcal::ros2 {
namespace {

using testing::TempDir;

#define SKIP_WITHOUT_ORACLE()                                         \
  if (const std::string missing = testing::Ros2OracleMissing();       \
      !missing.empty()) {                                             \
    GTEST_SKIP() << missing;                                          \
  }

class SqliteOracle : public ::testing::TestWithParam<const char*> {};

TEST_P(SqliteOracle, EveryValueReadEqualsWhatTheLibraryWrote) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  const std::string bag = dir.File("bag");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, std::string("--format=sqlite3 ") + GetParam(),
                                    dir.File("expected.txt"), &error))
      << error;
  SqliteBagReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.TopicNames(),
            (std::vector<std::string>{"/chatter", "/hesai/pandar", "/imu", "/ouster/points",
                                      "/velodyne_points"}));
  EXPECT_EQ(reader.TopicType("/imu"), kImuType);
  EXPECT_EQ(reader.TopicsOfType(kPointCloud2Type).size(), 3u);
  EXPECT_EQ(reader.MessageCount("/imu"), 40);
  EXPECT_EQ(reader.MessageCount("/ouster/points"), 3);
  EXPECT_EQ(reader.TotalMessageCount(), 54);
  int count = 0;
  EXPECT_EQ(testing::CompareWithExpected(&reader, dir.File("expected.txt"), &count), "");
  EXPECT_EQ(count, 54);
}

// One file; three files (messages in time order across files); big endian.
INSTANTIATE_TEST_SUITE_P(Layouts, SqliteOracle,
                         ::testing::Values("", "--split=20", "--big-endian --split=7"));

TEST(SqliteBagReader, SelectsTopicsAndRecordTimeWindow) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir.File("bag"), "--format=sqlite3 --split=10", "", &error))
      << error;
  SqliteBagReader reader;
  ASSERT_TRUE(reader.Open(dir.File("bag")).ok());
  ASSERT_EQ(reader.files().size(), 6u);
  int64_t start = 0, end = 0;
  ASSERT_TRUE(reader.TimeRange(&start, &end));
  EXPECT_EQ(start, 1700000000000000007LL);  // the first /chatter message
  bag::MessageSelection selection;
  selection.topics = {"/imu"};
  selection.start_ns = 1700000000000000000LL + 10 * 5000000LL + 1000000LL;
  selection.end_ns = selection.start_ns + 5 * 5000000LL;
  std::vector<int64_t> times;
  ASSERT_TRUE(reader
                  .ReadMessages(selection,
                                [&](const bag::Message& m) {
                                  EXPECT_EQ(*m.topic, "/imu");
                                  EXPECT_EQ(m.sequence, times.size());
                                  times.push_back(m.time_ns);
                                  return Status::Ok();
                                })
                  .ok());
  ASSERT_EQ(times.size(), 5u);
  EXPECT_EQ(times.front(), selection.start_ns);
}

TEST(SqliteBagReader, OpensASingleDb3File) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir.File("bag"), "--format=sqlite3", "", &error)) << error;
  SqliteBagReader reader;
  const Status status = reader.Open(dir.File("bag/bag_0.db3"));
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.TotalMessageCount(), 54);
}

TEST(SqliteBagReader, ReadsTheTalkerFixture) {
  const std::string fixtures = testing::SharedFixturesDir();
  if (fixtures.empty()) GTEST_SKIP() << "no ../shared/fixtures";
  const std::string bag = fixtures + "/bags/ros2/sqlite3_talker";
  if (!testing::FileExists(bag + "/talker.db3")) GTEST_SKIP() << "no " << bag;
  SqliteBagReader reader;
  const Status status = reader.Open(bag);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.TopicNames(),
            (std::vector<std::string>{"/parameter_events", "/rosout", "/topic"}));
  EXPECT_EQ(reader.TopicType("/topic"), "std_msgs/msg/String");
  EXPECT_EQ(reader.MessageCount("/topic"), 10);
  EXPECT_EQ(reader.MessageCount("/rosout"), 10);
  EXPECT_EQ(reader.MessageCount("/parameter_events"), 0);
  int64_t start = 0, end = 0;
  ASSERT_TRUE(reader.TimeRange(&start, &end));
  EXPECT_EQ(start, 1585866235112411371LL);  // metadata.yaml: starting_time
  EXPECT_EQ(end - start, 4531096768LL);     // metadata.yaml: duration
  std::vector<std::string> texts;
  int64_t last = 0;
  ASSERT_TRUE(reader
                  .ReadMessages({{"/topic"}},
                                [&](const bag::Message& m) {
                                  EXPECT_GE(m.time_ns, last);
                                  last = m.time_ns;
                                  CdrReader r;
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
}

TEST(SqliteBagReader, GarbageFileIsAnErrorNamingIt) {
  TempDir dir;
  std::ofstream(dir.File("x.db3")) << std::string(4096, 'x');
  SqliteBagReader reader;
  const Status status = reader.Open(dir.File("x.db3"));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(dir.File("x.db3")), std::string::npos) << status.message();
}

TEST(SqliteBagReader, MetadataListingAMissingFileIsAnError) {
  TempDir dir;
  std::ofstream(dir.File("metadata.yaml"))
      << "rosbag2_bagfile_information:\n  relative_file_paths:\n    - gone_0.db3\n";
  SqliteBagReader reader;
  const Status status = reader.Open(dir.path());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("gone_0.db3"), std::string::npos) << status.message();
}

TEST(SqliteBagReader, CompressedBagIsAnError) {
  TempDir dir;
  std::ofstream(dir.File("metadata.yaml"))
      << "rosbag2_bagfile_information:\n  relative_file_paths:\n    - a_0.db3.zstd\n"
         "  compression_format: zstd\n  compression_mode: FILE\n";
  SqliteBagReader reader;
  const Status status = reader.Open(dir.path());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("compression_format 'zstd'"), std::string::npos)
      << status.message();
}

TEST(SqliteBagReader, TruncatedFileIsAnErrorNamingIt) {
  SKIP_WITHOUT_ORACLE();
  TempDir dir;
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir.File("bag"), "--format=sqlite3", "", &error)) << error;
  const std::string db = dir.File("bag/bag_0.db3");
  std::filesystem::resize_file(db, std::filesystem::file_size(db) / 2);
  SqliteBagReader reader;
  Status status = reader.Open(db);
  if (status.ok()) {
    status = reader.ReadMessages({}, [](const bag::Message&) { return Status::Ok(); });
  }
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find(db), std::string::npos) << status.message();
}

}  // namespace
}  // namespace tiltcal::ros2
