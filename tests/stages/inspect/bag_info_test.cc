// `tiltcal_inspect info --bag` held to other tools: on every bag rosbag2
// recorded for its own tests (../shared/fixtures/bags/ros2/rosbag2_tests/,
// sqlite3 and MCAP) it agrees with the bag's metadata.yaml as PyYAML reads
// it (topics, types, counts, span) without a warning, counts the messages of
// types it does not read (cdr_test's test_msgs) and refuses the bag
// recorded with another RMW's serialisation in one line naming it; on every
// ROS 1 fixture it agrees with the real ROS library (python3-rosbag:
// topics, types, counts, rates, times) and deserialises every message of a
// type decode reads. The oracle is tests/oracle/bag_info_oracle.py.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "stages/inspect/bag_info_report.h"
#include "tests/testing/json_value.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

namespace fs = std::filesystem;
using testing::JsonValue;

constexpr int kOracleMissing = 3;  // bag_info_oracle.py: the library is missing

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Runs `command` with stdout to a file and parses it as JSON; *rc gets the
// exit status, *diagnostics stderr.
JsonValue RunForJson(const std::string& command, const testing::TempDir& dir, int* rc,
                     std::string* diagnostics) {
  const std::string out = dir.File("out.json");
  *rc = testing::RunCommand("(" + command + " > " + out + ")", diagnostics);
  JsonValue value;
  std::string error;
  if (*rc == 0) {
    EXPECT_TRUE(testing::ParseJson(ReadText(out), &value, &error))
        << command << ": " << error << "\n"
        << ReadText(out);
  }
  return value;
}

int64_t Int(const JsonValue* v) {
  return v == nullptr || v->kind != JsonValue::Kind::kNumber ? INT64_MIN : std::stoll(v->text);
}

// The topic `name` of info's JSON; nullptr when absent.
const JsonValue* InfoTopic(const JsonValue& info, const std::string& name) {
  for (const JsonValue& t : info.Find("topics")->items) {
    if (t.Find("name")->text == name) return &t;
  }
  return nullptr;
}

std::string InfoCommand(const std::string& bag) {
  return testing::ToolPath("tiltcal_inspect") + " info --format=json --bag=" + bag;
}

std::string OracleCommand(const std::string& mode, const std::string& path) {
  return std::string(testing::kDebianPython) + " " + testing::SourceDir() +
         "/tests/oracle/bag_info_oracle.py " + mode + " " + path;
}

class BagInfo : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(testing::FileExists(testing::ToolPath("tiltcal_inspect")))
        << "build tiltcal_inspect first";
    fixtures_ = testing::SharedFixturesDir();
  }
  std::string fixtures_;
  testing::TempDir dir_;
};

TEST_F(BagInfo, AgreesWithTheMetadataOfRosbag2sOwnTestBags) {
  const std::string root = fixtures_ + "/bags/ros2/rosbag2_tests";
  if (fixtures_.empty() || !fs::is_directory(root)) GTEST_SKIP() << "no " << root;
  int bags = 0;
  for (const char* storage : {"sqlite3", "mcap"}) {
    for (const char* name : {"cdr_test", "bag_with_topics_and_service_events"}) {
      const std::string bag = root + "/" + storage + "/" + name;
      SCOPED_TRACE(bag);
      int rc = 0;
      std::string diagnostics;
      const JsonValue yaml = RunForJson(OracleCommand("rosbag2-metadata", bag), dir_, &rc,
                                        &diagnostics);
      if (rc == kOracleMissing) GTEST_SKIP() << "/usr/bin/python3 cannot import yaml";
      ASSERT_EQ(rc, 0) << diagnostics;
      const JsonValue info = RunForJson(InfoCommand(bag), dir_, &rc, &diagnostics);
      ASSERT_EQ(rc, 0) << diagnostics;
      ASSERT_EQ(info.kind, JsonValue::Kind::kObject);
      ASSERT_EQ(yaml.kind, JsonValue::Kind::kObject);
      EXPECT_EQ(info.Find("warnings")->items.size(), 0u) << ReadText(dir_.File("out.json"));
      EXPECT_EQ(Int(info.Find("message_count")), Int(yaml.Find("message_count")));
      EXPECT_EQ(Int(info.Find("start_ns")), Int(yaml.Find("starting_time_ns")));
      EXPECT_EQ(Int(info.Find("duration_ns")), Int(yaml.Find("duration_ns")));
      // Every topic of the metadata, with its type and count (a topic that
      // the metadata lists with no message may be absent from the files).
      for (const auto& [topic, figures] : yaml.Find("topics")->members) {
        const JsonValue* t = InfoTopic(info, topic);
        if (Int(figures.Find("message_count")) == 0 && t == nullptr) continue;
        ASSERT_NE(t, nullptr) << topic;
        EXPECT_EQ(t->Find("type")->text, figures.Find("type")->text) << topic;
        EXPECT_EQ(Int(t->Find("message_count")), Int(figures.Find("message_count"))) << topic;
        // Types decode does not read are counted, not deserialised.
        EXPECT_EQ(t->Find("sensor_type")->kind, JsonValue::Kind::kBool);
        EXPECT_FALSE(t->Find("sensor_type")->boolean) << topic;
        EXPECT_EQ(Int(t->Find("decoded")), 0) << topic;
      }
      for (const JsonValue& t : info.Find("topics")->items) {
        EXPECT_NE(yaml.Find("topics")->Find(t.Find("name")->text), nullptr)
            << t.Find("name")->text << " is not in metadata.yaml";
      }
      // The metadata's own figures, as info read them, beside the files'.
      const JsonValue* stated = info.Find("rosbag2_metadata");
      ASSERT_EQ(stated->kind, JsonValue::Kind::kObject);
      EXPECT_EQ(stated->Find("storage_identifier")->text, storage);
      EXPECT_EQ(Int(stated->Find("message_count")), Int(yaml.Find("message_count")));
      ++bags;
    }
  }
  EXPECT_EQ(bags, 4);
}

TEST_F(BagInfo, CdrTestMessagesAreCountedAndTheTextSaysNoWarning) {
  const std::string root = fixtures_ + "/bags/ros2/rosbag2_tests";
  if (fixtures_.empty() || !fs::is_directory(root)) GTEST_SKIP() << "no " << root;
  for (const char* storage : {"sqlite3", "mcap"}) {
    const std::string bag = root + "/" + storage + "/cdr_test";
    std::string output;
    ASSERT_EQ(testing::RunCommand(testing::ToolPath("tiltcal_inspect") + " info --bag=" + bag,
                                  &output),
              0)
        << output;
    EXPECT_NE(output.find("messages     7\n"), std::string::npos) << output;
    EXPECT_NE(output.find("span         1586406456.763032325 .. 1586406456.914169506 s "
                          "(0.151137181 s)"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("/array_topic  test_msgs/msg/Arrays      4         cdr"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("warnings     none\n"), std::string::npos) << output;
  }
}

// rosbag2's wrong-RMW bag names the serialisation "wrong_format" in its
// metadata.yaml; the sqlite3 file's topics table says cdr (the messages are
// CDR and are read, with a warning per topic), the MCAP file's channels say
// wrong_format (refused in one line).
TEST_F(BagInfo, WrongRmwBagGetsAClearLine) {
  const std::string root = fixtures_ + "/bags/ros2/rosbag2_tests";
  if (fixtures_.empty() || !fs::is_directory(root)) GTEST_SKIP() << "no " << root;
  const std::string inspect = testing::ToolPath("tiltcal_inspect") + " info --bag=";
  std::string output;
  ASSERT_EQ(testing::RunCommand(inspect + root + "/sqlite3/wrong_rmw_test", &output), 0)
      << output;
  for (const char* topic : {"/test_topic", "/array_topic"}) {
    EXPECT_NE(output.find(std::string("\nwarning: metadata.yaml: topic '") + topic +
                          "' serialised as 'wrong_format', the files hold cdr\n"),
              std::string::npos)
        << output;
  }
  EXPECT_NE(output.find("warnings     2\n"), std::string::npos) << output;
  output.clear();
  const std::string mcap = root + "/mcap/wrong_rmw_test";
  EXPECT_EQ(testing::RunCommand("(" + inspect + mcap + " > /dev/null)", &output), 1) << output;
  EXPECT_EQ(output, "tiltcal_inspect: " + mcap +
                        "/wrong_rmw_test_0.mcap: channel 1 (topic '/test_topic') has message "
                        "encoding 'wrong_format'; only cdr (ROS 2) and ros1 are read\n");
}

TEST_F(BagInfo, AgreesWithRosbagOnEveryRos1Fixture) {
  const std::string root = fixtures_ + "/bags/ros1";
  if (fixtures_.empty() || !fs::is_directory(root)) GTEST_SKIP() << "no " << root;
  if (!testing::HaveRosbagPython()) GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag";
  std::vector<std::string> bags;
  for (const auto& entry : fs::directory_iterator(root)) {
    if (entry.path().extension() == ".bag") bags.push_back(entry.path().string());
  }
  std::sort(bags.begin(), bags.end());
  ASSERT_EQ(bags.size(), 8u);
  int rc = 0;
  std::string diagnostics;
  std::string all;
  for (const std::string& bag : bags) all += " " + bag;
  const JsonValue oracle = RunForJson(OracleCommand("rosbag", all), dir_, &rc, &diagnostics);
  ASSERT_EQ(rc, 0) << diagnostics;
  ASSERT_EQ(oracle.kind, JsonValue::Kind::kObject);
  int sensor_topics = 0;
  for (const std::string& bag : bags) {
    SCOPED_TRACE(bag);
    ASSERT_NE(oracle.Find(bag), nullptr);
    const JsonValue& rosbag = *oracle.Find(bag);
    const JsonValue info = RunForJson(InfoCommand(bag), dir_, &rc, &diagnostics);
    ASSERT_EQ(rc, 0) << diagnostics;
    ASSERT_EQ(info.kind, JsonValue::Kind::kObject);
    EXPECT_EQ(info.Find("warnings")->items.size(), 0u) << ReadText(dir_.File("out.json"));
    EXPECT_EQ(info.Find("format")->text, "ROS 1 bag");
    EXPECT_EQ(Int(info.Find("message_count")), Int(rosbag.Find("message_count")));
    EXPECT_EQ(info.Find("start_ns")->text, rosbag.Find("start_ns")->text);
    EXPECT_EQ(info.Find("end_ns")->text, rosbag.Find("end_ns")->text);
    EXPECT_EQ(info.Find("topics")->items.size(), rosbag.Find("topics")->members.size());
    for (const auto& [topic, figures] : rosbag.Find("topics")->members) {
      const JsonValue* t = InfoTopic(info, topic);
      ASSERT_NE(t, nullptr) << topic;
      EXPECT_EQ(t->Find("type")->text, figures.Find("type")->text) << topic;
      EXPECT_EQ(Int(t->Find("message_count")), Int(figures.Find("message_count"))) << topic;
      EXPECT_EQ(t->Find("start_ns")->text, figures.Find("start_ns")->text) << topic;
      EXPECT_EQ(t->Find("end_ns")->text, figures.Find("end_ns")->text) << topic;
      const double rate = std::stod(t->Find("rate_hz")->text);
      const JsonValue* frequency = figures.Find("frequency");
      if (frequency->kind == JsonValue::Kind::kNull) {
        // rosbag takes the intervals in the order of its index, which is not
        // the time order where chunks are out of order (one negative
        // interval then makes its median zero or less): info's rate is of
        // the record times in order.
        if (figures.Find("in_time_order")->boolean) {
          EXPECT_EQ(rate, 0.0) << topic;
        }
      } else {
        // rosbag takes the intervals of times in float seconds since the
        // epoch: each off by up to two units in the last place of the end
        // time, the rate by rate² times that.
        const double end_s = 1e-9 * static_cast<double>(Int(figures.Find("end_ns")));
        const double ulp = std::nextafter(end_s, 2 * end_s + 1) - end_s;
        EXPECT_NEAR(rate, std::stod(frequency->text), rate * rate * 2 * ulp + 1e-12 * rate)
            << topic;
      }
      if (t->Find("sensor_type")->boolean) {
        ++sensor_topics;
        EXPECT_EQ(Int(t->Find("decoded")), Int(t->Find("message_count"))) << topic;
        EXPECT_EQ(t->Find("decode_error")->text, "") << topic;
      }
    }
  }
  EXPECT_GE(sensor_topics, 5);  // Imu, PointCloud2 and TFMessage topics among them
}

// The other shapes decode reads: a plain .mcap, a single .db3, a folder of
// bag files (two of them the same recording: the duplicates counted once,
// with a warning), a Livox bag (CustomMsg deserialised; one whose
// point_num disagrees with its points is a warning naming the message).
TEST_F(BagInfo, EveryInputShape) {
  if (fixtures_.empty()) GTEST_SKIP() << "no ../shared/fixtures";
  const std::string bags = fixtures_ + "/bags";
  int rc = 0;
  std::string diagnostics;
  JsonValue info = RunForJson(InfoCommand(bags + "/ros2/mcap_talker/talker.mcap"), dir_, &rc,
                              &diagnostics);
  ASSERT_EQ(rc, 0) << diagnostics;
  ASSERT_EQ(info.kind, JsonValue::Kind::kObject);
  EXPECT_EQ(info.Find("format")->text, "MCAP");
  EXPECT_EQ(Int(info.Find("chunk_compressions")->Find("zstd")), 1);
  EXPECT_EQ(Int(info.Find("message_count")), 20);
  ASSERT_NE(InfoTopic(info, "/topic"), nullptr);
  EXPECT_EQ(InfoTopic(info, "/topic")->Find("type")->text, "std_msgs/msg/String");
  EXPECT_EQ(InfoTopic(info, "/topic")->Find("encoding")->text, "cdr");
  EXPECT_EQ(Int(InfoTopic(info, "/topic")->Find("message_count")), 10);
  EXPECT_EQ(info.Find("warnings")->items.size(), 0u);

  info = RunForJson(InfoCommand(bags + "/ros2/sqlite3_talker/talker.db3"), dir_, &rc,
                    &diagnostics);
  ASSERT_EQ(rc, 0) << diagnostics;
  ASSERT_EQ(info.kind, JsonValue::Kind::kObject);
  EXPECT_EQ(info.Find("format")->text, "rosbag2 sqlite3");
  EXPECT_EQ(Int(info.Find("message_count")), 20);
  EXPECT_EQ(info.Find("rosbag2_metadata")->kind, JsonValue::Kind::kNull);  // a file, no folder

  info = RunForJson(InfoCommand(bags + "/ros1"), dir_, &rc, &diagnostics);
  ASSERT_EQ(rc, 0) << diagnostics;
  ASSERT_EQ(info.kind, JsonValue::Kind::kObject);
  EXPECT_EQ(info.Find("format")->text, "8 files (ROS 1 bag)");
  EXPECT_EQ(info.Find("files")->items.size(), 8u);
  // rosbagjs_example-bz2 and -lz4 hold the same 8647 messages.
  EXPECT_EQ(Int(info.Find("duplicates_dropped")), 8647);
  EXPECT_EQ(Int(info.Find("message_count")), 1465 + 15 + 6121 + 9 + 8647 + 3);
  ASSERT_EQ(info.Find("warnings")->items.size(), 1u);
  EXPECT_EQ(info.Find("warnings")->items[0].text,
            "8647 messages held by two files of the folder (same topic, time and bytes) counted "
            "once");

  if (!testing::HaveRosbagPython()) GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag";
  for (const std::string bad : {"", "point_num"}) {
    SCOPED_TRACE("livox " + bad);
    const std::string bag = dir_.File("livox" + bad + ".bag");
    ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                  testing::SourceDir() + "/tests/oracle/write_livox_bag.py " +
                                  bag + " " + dir_.File("expected.txt") +
                                  (bad.empty() ? "" : " --bad=" + bad) + " > /dev/null"),
              0);
    info = RunForJson(InfoCommand(bag), dir_, &rc, &diagnostics);
    ASSERT_EQ(rc, 0) << diagnostics;
    ASSERT_EQ(info.kind, JsonValue::Kind::kObject);
    const JsonValue* lidar = InfoTopic(info, "/livox/lidar");
    ASSERT_NE(lidar, nullptr);
    EXPECT_EQ(lidar->Find("type")->text, "livox_ros_driver/CustomMsg");
    EXPECT_EQ(Int(lidar->Find("message_count")), 4);
    EXPECT_NEAR(std::stod(lidar->Find("rate_hz")->text), 10.0, 1e-6);
    EXPECT_EQ(Int(lidar->Find("decoded")), bad.empty() ? 4 : 3);
    EXPECT_EQ(Int(InfoTopic(info, "/imu")->Find("decoded")), 60);
    if (bad.empty()) {
      EXPECT_EQ(info.Find("warnings")->items.size(), 0u);
    } else {
      ASSERT_EQ(info.Find("warnings")->items.size(), 1u);
      EXPECT_EQ(info.Find("warnings")->items[0].text.rfind(
                    "topic '/livox/lidar': 1 of 4 messages do not deserialise as "
                    "livox_ros_driver/CustomMsg; the first: message 1 (chunk at byte ",
                    0),
                0u)
          << info.Find("warnings")->items[0].text;
    }
  }
}

TEST_F(BagInfo, AnUnknownFormatIsAUsageError) {
  std::string output;
  EXPECT_EQ(testing::RunCommand(testing::ToolPath("tiltcal_inspect") +
                                    " info --bag=any.bag --format=yaml",
                                &output),
            2);
  EXPECT_EQ(output, "tiltcal_inspect: --format=yaml: expected text or json\n");
}

// A hostile name stays data: the JSON gives it back, the text keeps it on
// its own line.
TEST(BagInfoReport, NamesFromTheBagStayData) {
  inspect::BagInfo info;
  info.path = "run\n1.bag";
  info.format = "MCAP";
  info.files = {info.path};
  info.message_count = 2;
  info.first_ns = -1500000000;
  info.last_ns = 2;
  inspect::TopicFigures topic;
  topic.name = "/imu\nwarning: forged \"\x01";
  topic.type = "sensor_msgs/msg/Imu";
  topic.encoding = "cdr";
  topic.count = topic.indexed_count = 2;
  topic.first_ns = info.first_ns;
  topic.last_ns = info.last_ns;
  info.topics = {topic};
  info.warnings = {"topic '" + topic.name + "': something"};
  std::ostringstream json;
  inspect::WriteBagInfoJson(info, json);
  JsonValue value;
  std::string error;
  ASSERT_TRUE(testing::ParseJson(json.str(), &value, &error)) << error << "\n" << json.str();
  EXPECT_EQ(value.Find("path")->text, info.path);
  EXPECT_EQ(value.Find("topics")->items.at(0).Find("name")->text, topic.name);
  EXPECT_EQ(value.Find("start_ns")->text, "-1500000000");
  EXPECT_EQ(value.Find("warnings")->items.at(0).text, info.warnings[0]);
  std::ostringstream text;
  inspect::WriteBagInfoText(info, text);
  EXPECT_NE(text.str().find("span         -1.500000000 .. 0.000000002 s (1.500000002 s)\n"),
            std::string::npos)
      << text.str();
  EXPECT_NE(text.str().find("/imu\\x0awarning: forged \"\\x01"), std::string::npos) << text.str();
  EXPECT_EQ(text.str().find("\nwarning: forged"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find("warnings     1\nwarning: topic '/imu\\x0awarning"), std::string::npos)
      << text.str();
}

}  // namespace
}  // namespace tiltcal
