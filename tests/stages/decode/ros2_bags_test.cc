// tiltcal_decode on ROS 2 bags as a user runs it: a simulated sequence
// (tiltcal_simulate writes ROS 1) converted to MCAP, to a rosbag2 sqlite3
// folder and to MCAP with ROS 1 messages by the reference libraries
// (tests/oracle/ros1_bag_to_ros2_jsonl.py with python3-rosbag, then
// write_ros2_bags.mjs) decodes to a byte-identical imu.binpb (after the
// header, whose provenance names the input) and the same scans as the ROS 1
// bag; bad ROS 2 input gives one error line naming the file, exit 1 and no
// output.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/stream_bytes.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/scan.pb.h"
#include "tiltcal/proto/simulate_params.pb.h"

namespace tiltcal {
namespace {

namespace fs = std::filesystem;
using testing::ToolPath;

// Decodes `bag` into dir/out_<name>/; returns the exit status.
int Decode(const testing::TempDir& dir, const std::string& bag, const std::string& name,
           std::string* output) {
  fs::create_directories(dir.File("out_" + name));
  return testing::RunCommand(ToolPath("tiltcal_decode") + " --bag='" + bag + "' --rig=" +
                                 dir.File("rig.txtpb") + " --out_imu=" +
                                 dir.File("out_" + name + "/imu.binpb") + " --out_scans=" +
                                 dir.File("out_" + name + "/scans.binpb.lz4") + " 2>&1",
                             output);
}

TEST(DecodeRos2Bags, SimulatedSequenceDecodesIdenticallyFromRos1McapAndSqlite) {
  if (const std::string missing = testing::Ros2OracleMissing(); !missing.empty()) {
    GTEST_SKIP() << missing;
  }
  if (!testing::HaveRosbagPython()) GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag";
  for (const char* tool : {"tiltcal_simulate", "tiltcal_decode"}) {
    ASSERT_TRUE(testing::FileExists(ToolPath(tool))) << "build " << tool << " first";
  }
  testing::TempDir dir;
  proto::SimulateParams scenario;
  ASSERT_TRUE(ReadTextProto(
                  testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb",
                  &scenario)
                  .ok());
  scenario.set_duration_s(2.0);
  scenario.set_num_threads(1);
  ASSERT_TRUE(WriteTextProto(dir.File("scenario.txtpb"), scenario).ok());
  std::string output;
  ASSERT_EQ(testing::RunCommand(ToolPath("tiltcal_simulate") + " --quiet --params=" +
                                    dir.File("scenario.txtpb") + " --out_bag=" +
                                    dir.File("run.bag") + " --out_truth=" +
                                    dir.File("truth.txtpb") + " --out_rig=" +
                                    dir.File("rig.txtpb") + " 2>&1",
                                &output),
            0)
      << output;
  ASSERT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                    testing::SourceDir() +
                                    "/tests/oracle/ros1_bag_to_ros2_jsonl.py " +
                                    dir.File("run.bag") + " > " + dir.File("run.jsonl")),
            0);
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(dir.File("run.mcap"),
                                    "--format=mcap --compression=lz4 --messages=" +
                                        dir.File("run.jsonl"),
                                    "", &error))
      << error;
  // A ROS 1 bag as converted to MCAP: ROS 1 messages ("ros1" encoding).
  ASSERT_TRUE(testing::WriteRos2Bag(dir.File("run_ros1.mcap"),
                                    "--format=mcap --encoding=ros1 --compression=zstd "
                                    "--messages=" +
                                        dir.File("run.jsonl"),
                                    "", &error))
      << error;
  // Three .db3 files: the messages are merged across them in time order.
  ASSERT_TRUE(testing::WriteRos2Bag(dir.File("run_ros2"),
                                    "--format=sqlite3 --split=200 --messages=" +
                                        dir.File("run.jsonl"),
                                    "", &error))
      << error;

  const std::vector<std::pair<std::string, std::string>> inputs = {
      {"ros1", dir.File("run.bag")},
      {"mcap", dir.File("run.mcap")},
      {"sqlite3", dir.File("run_ros2")},
      {"mcap_ros1", dir.File("run_ros1.mcap")}};
  for (const auto& [name, bag] : inputs) {
    ASSERT_EQ(Decode(dir, bag, name, &output), 0) << name << ": " << output;
  }
  const auto imu =
      testing::SerializedRecords<proto::ImuSample>(dir.File("out_ros1/imu.binpb"));
  const auto scans =
      testing::SerializedRecords<proto::Scan>(dir.File("out_ros1/scans.binpb.lz4"));
  ASSERT_GT(imu.size(), 300u);
  ASSERT_GT(scans.size(), 15u);
  const std::string imu_bytes = testing::StreamBytesAfterHeader(dir.File("out_ros1/imu.binpb"));
  ASSERT_GT(imu_bytes.size(), 10000u);
  for (const char* name : {"mcap", "sqlite3", "mcap_ros1"}) {
    const std::string out = dir.File(std::string("out_") + name);
    EXPECT_TRUE(testing::StreamBytesAfterHeader(out + "/imu.binpb") == imu_bytes)
        << name << ": imu.binpb is not byte-identical to the ROS 1 bag's";
    EXPECT_TRUE(testing::SerializedRecords<proto::ImuSample>(out + "/imu.binpb") == imu)
        << name;
    EXPECT_TRUE(testing::SerializedRecords<proto::Scan>(out + "/scans.binpb.lz4") == scans) << name;
  }
}

class DecodeRos2BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(testing::FileExists(ToolPath("tiltcal_decode"))) << "build tiltcal_decode first";
  }
  // One line naming every string of `must_contain`, exit 1, nothing in out_bad/.
  void ExpectCleanFailure(const std::string& bag, const std::vector<std::string>& must_contain,
                          const std::string& params = "") {
    std::string output;
    const int rc = testing::RunCommand(
        ToolPath("tiltcal_decode") + " --bag='" + bag + "'" +
            (params.empty() ? "" : " --params=" + params) + " --out_imu=" +
            dir_.File("out_bad/imu.binpb") + " --out_scans=" +
            dir_.File("out_bad/scans.binpb.lz4") + " 2>&1",
        &output);
    EXPECT_EQ(rc, 1) << output;
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    for (const std::string& s : must_contain) {
      EXPECT_NE(output.find(s), std::string::npos) << "'" << s << "' not in: " << output;
    }
    EXPECT_TRUE(fs::is_empty(dir_.File("out_bad"))) << "output left behind";
  }
  void SetUpOutDir() { fs::create_directories(dir_.File("out_bad")); }

  testing::TempDir dir_;
};

TEST_F(DecodeRos2BadInput, TalkerFixturesHaveNoImuTopic) {
  const std::string fixtures = testing::SharedFixturesDir();
  if (fixtures.empty()) GTEST_SKIP() << "no ../shared/fixtures";
  SetUpOutDir();
  for (const char* bag : {"/bags/ros2/sqlite3_talker", "/bags/ros2/mcap_talker"}) {
    ExpectCleanFailure(fixtures + bag,
                       {"no sensor_msgs/msg/Imu topic", "/topic", "/rosout"});
  }
}

TEST_F(DecodeRos2BadInput, TruncatedMcapHeaderNamesFileAndByte) {
  SetUpOutDir();
  const std::string bag = dir_.File("cut.mcap");
  std::ofstream(bag, std::ios::binary) << std::string("\x89MCAP0\r\n\x01\xff\x00", 11);
  ExpectCleanFailure(bag, {bag + ": byte 8: ", "runs past"});
}

TEST_F(DecodeRos2BadInput, CorruptedMcapChunkNamesFileAndByte) {
  if (const std::string missing = testing::Ros2OracleMissing(); !missing.empty()) {
    GTEST_SKIP() << missing;
  }
  SetUpOutDir();
  const std::string bag = dir_.File("bad.mcap");
  std::string error;
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=mcap", "", &error)) << error;
  {
    std::fstream f(bag, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(6000);  // inside the first chunk's point-cloud data
    f.put('\x5A');
  }
  // The oracle bag has three PointCloud2 topics: choose one.
  // The defaults with lidar_topic replaced (a field given twice is an error).
  std::ifstream defaults(testing::SourceDir() + "/stages/decode/default_params.txtpb");
  std::string text((std::istreambuf_iterator<char>(defaults)), std::istreambuf_iterator<char>());
  const std::string line = "lidar_topic: \"\"";
  ASSERT_NE(text.find(line), std::string::npos);
  text.replace(text.find(line), line.size(), "lidar_topic: \"/velodyne_points\"");
  std::ofstream(dir_.File("params.txtpb")) << text;
  ExpectCleanFailure(bag, {bag + ": byte ", "CRC mismatch"}, dir_.File("params.txtpb"));
}

TEST_F(DecodeRos2BadInput, GarbageDb3AndFolderWithoutMetadataAreErrors) {
  SetUpOutDir();
  const std::string db3 = dir_.File("x.db3");
  std::ofstream(db3, std::ios::binary) << std::string("SQLite format 3\0", 16)
                                       << std::string(2000, 'x');
  ExpectCleanFailure(db3, {db3});
  fs::create_directories(dir_.File("empty_bag"));
  ExpectCleanFailure(dir_.File("empty_bag"), {dir_.File("empty_bag"), "metadata.yaml"});
}

}  // namespace
}  // namespace tiltcal
