// The figures a rosbag2 metadata.yaml states, from the layout rosbag2
// writes: nested blocks, lists of topics, quoted values, the per-file list
// that repeats the same keys deeper, and values that are not numbers.
#include "bag/ros2/rosbag2_metadata_figures.h"

#include <string>

#include <gtest/gtest.h>

namespace tiltcal::ros2 {
namespace {

constexpr char kWritten[] =
    "rosbag2_bagfile_information:\n"
    "  version: 8\n"
    "  storage_identifier: sqlite3\n"
    "  duration:\n"
    "    nanoseconds: 70633730\n"
    "  starting_time:\n"
    "    nanoseconds_since_epoch: 1699345836023194036\n"
    "  message_count: 10\n"
    "  topics_with_message_count:\n"
    "    - topic_metadata:\n"
    "        name: /events/write_split\n"
    "        type: rosbag2_interfaces/msg/WriteSplitEvent\n"
    "        serialization_format: cdr\n"
    "        offered_qos_profiles: \"- history: 3\\n  depth: 0\"\n"
    "        type_description_hash: RIHS01_5ef5\n"
    "      message_count: 0\n"
    "    - topic_metadata:\n"
    "        name: \"/test_topic1\"\n"
    "        type: test_msgs/msg/Strings\n"
    "        serialization_format: cdr\n"
    "      message_count: 10\n"
    "  compression_format: \"\"\n"
    "  compression_mode: \"\"\n"
    "  relative_file_paths:\n"
    "    - a.db3\n"
    "  files:\n"
    "    - path: a.db3\n"
    "      starting_time:\n"
    "        nanoseconds_since_epoch: 5\n"
    "      duration:\n"
    "        nanoseconds: 6\n"
    "      message_count: 7\n"
    "  custom_data: ~\n";

TEST(Rosbag2Figures, EveryFigureOfTheLayoutRosbag2Writes) {
  const Rosbag2Figures f = ParseRosbag2Figures(kWritten);
  EXPECT_EQ(f.version, 8);
  EXPECT_EQ(f.storage_identifier, "sqlite3");
  EXPECT_EQ(f.duration_ns, 70633730);
  EXPECT_EQ(f.starting_time_ns, 1699345836023194036);
  EXPECT_EQ(f.message_count, 10);  // not the per-file 7
  EXPECT_EQ(f.compression_format, "");
  ASSERT_EQ(f.topics.size(), 2u);
  EXPECT_EQ(f.topics[0].name, "/events/write_split");
  EXPECT_EQ(f.topics[0].type, "rosbag2_interfaces/msg/WriteSplitEvent");
  EXPECT_EQ(f.topics[0].serialization_format, "cdr");
  EXPECT_EQ(f.topics[0].message_count, 0);
  EXPECT_EQ(f.topics[1].name, "/test_topic1");
  EXPECT_EQ(f.topics[1].message_count, 10);
  EXPECT_TRUE(f.unreadable.empty());
}

TEST(Rosbag2Figures, MissingAndUnreadableFiguresAreSaid) {
  const Rosbag2Figures f = ParseRosbag2Figures(
      "rosbag2_bagfile_information:\n  message_count: many\n  storage_identifier: mcap\n");
  EXPECT_EQ(f.message_count, -1);
  EXPECT_EQ(f.duration_ns, -1);
  EXPECT_EQ(f.starting_time_ns, -1);
  EXPECT_EQ(f.storage_identifier, "mcap");
  ASSERT_EQ(f.unreadable.size(), 1u);
  EXPECT_EQ(f.unreadable[0], "message_count: many");
}

}  // namespace
}  // namespace tiltcal::ros2
