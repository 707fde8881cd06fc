// tiltcal_decode on one sequence split over several bag files, as a user
// runs it (--bag=FOLDER): a simulated sequence split by the reference
// libraries (tests/oracle/split_ros1_bag.py with python3-rosbag: by time
// with overlapping parts, and into imu.bag + lidar.bag; the npm writers: an
// MCAP part beside a .db3 part, and a rosbag2 MCAP folder of two files)
// decodes to byte-identical imu.binpb records and identical scans as the
// single bag; the provenance lists every file; a bad file in the folder is
// one error line naming it. Also decode's log for a complete MCAP without
// summary (no "salvaged") against a truncated one (salvaged).
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
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

// One simulated 2 s sequence (run.bag), its JSON lines for the ROS 2
// writers and its decoded outputs (out_single/), shared by the tests.
class DecodeSplitSequence : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!testing::HaveRosbagPython()) {
      skip_ = "/usr/bin/python3 cannot import rosbag";
      return;
    }
    for (const char* tool : {"tiltcal_simulate", "tiltcal_decode"}) {
      ASSERT_TRUE(testing::FileExists(ToolPath(tool))) << "build " << tool << " first";
    }
    dir_ = new testing::TempDir();
    proto::SimulateParams scenario;
    ASSERT_TRUE(ReadTextProto(
                    testing::SourceDir() + "/stages/simulate/scenarios/short_test_vlp16.txtpb",
                    &scenario)
                    .ok());
    scenario.set_duration_s(2.0);
    scenario.set_num_threads(1);
    ASSERT_TRUE(WriteTextProto(File("scenario.txtpb"), scenario).ok());
    std::string output;
    ASSERT_EQ(testing::RunCommand(ToolPath("tiltcal_simulate") + " --quiet --params=" +
                                      File("scenario.txtpb") + " --out_bag=" + File("run.bag") +
                                      " --out_truth=" + File("truth.txtpb") +
                                      " --out_rig=" + File("rig.txtpb") + " 2>&1",
                                  &output),
              0)
        << output;
    ASSERT_EQ(Decode(File("run.bag"), "single", &output), 0) << output;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (!skip_.empty()) GTEST_SKIP() << skip_;
    ASSERT_NE(dir_, nullptr);
  }

  static std::string File(const std::string& name) { return dir_->File(name); }

  // Decodes `bag` into out_<name>/; the exit status, the log in *output.
  static int Decode(const std::string& bag, const std::string& name, std::string* output) {
    fs::create_directories(File("out_" + name));
    return testing::RunCommand(ToolPath("tiltcal_decode") + " --bag='" + bag + "' --rig=" +
                                   File("rig.txtpb") + " --out_imu=" +
                                   File("out_" + name + "/imu.binpb") + " --out_scans=" +
                                   File("out_" + name + "/scans.binpb.lz4") + " 2>&1",
                               output);
  }

  // out_<name>/ holds exactly the single bag's IMU bytes and scans.
  static void ExpectSameAsSingleBag(const std::string& name) {
    const std::string imu = testing::StreamBytesAfterHeader(File("out_single/imu.binpb"));
    ASSERT_GT(imu.size(), 10000u);
    EXPECT_TRUE(testing::StreamBytesAfterHeader(File("out_" + name + "/imu.binpb")) == imu)
        << name << ": imu.binpb differs from the single bag's";
    const auto scans = testing::SerializedRecords<proto::Scan>(File("out_single/scans.binpb.lz4"));
    ASSERT_GT(scans.size(), 15u);
    EXPECT_TRUE(testing::SerializedRecords<proto::Scan>(File("out_" + name +
                                                             "/scans.binpb.lz4")) == scans)
        << name << ": scans differ from the single bag's";
  }

  // The "bag file" inputs of out_<name>/imu.binpb's provenance.
  static std::vector<std::string> ProvenanceFiles(const std::string& name) {
    std::vector<proto::ImuSample> samples;
    proto::StreamHeader header;
    EXPECT_TRUE(ReadAllRecords<proto::ImuSample>(File("out_" + name + "/imu.binpb"), &samples,
                                                 &header)
                    .ok());
    std::vector<std::string> files;
    for (const auto& input : header.provenance().inputs()) {
      if (input.role() == "bag file") files.push_back(input.path());
    }
    return files;
  }

  // Runs the ROS 1 splitter; its "messages M duplicated D" line.
  static std::string Split(const std::string& out, const std::string& args) {
    std::string output;
    EXPECT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                      testing::SourceDir() + "/tests/oracle/split_ros1_bag.py " +
                                      File("run.bag") + " " + out + " " + args + " 2>&1",
                                  &output),
              0)
        << output;
    return output;
  }

  // The sequence as JSON lines for write_ros2_bags.mjs (once).
  static std::string Jsonl() {
    const std::string jsonl = File("run.jsonl");
    if (!testing::FileExists(jsonl)) {
      EXPECT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                    testing::SourceDir() +
                                    "/tests/oracle/ros1_bag_to_ros2_jsonl.py " + File("run.bag") +
                                    " > " + jsonl),
                0);
    }
    return jsonl;
  }

  // The JSON lines split in two halves (first/second), by line.
  static void SplitJsonl(const std::string& first, const std::string& second) {
    std::ifstream in(Jsonl());
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    std::ofstream a(first), b(second);
    for (size_t i = 0; i < lines.size(); ++i) (i < lines.size() / 2 ? a : b) << lines[i] << "\n";
  }

  static testing::TempDir* dir_;
  static std::string skip_;
};

testing::TempDir* DecodeSplitSequence::dir_ = nullptr;
std::string DecodeSplitSequence::skip_;

TEST_F(DecodeSplitSequence, Ros1TimeSplitWithOverlapDecodesLikeTheSingleBag) {
  const std::string folder = File("split_time");
  const std::string split = Split(folder, "--by=time --parts=3 --overlap_s=0.25");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(split, match, std::regex("duplicated (\\d+)"))) << split;
  ASSERT_GT(std::stoi(match[1]), 50) << split;  // 0.25 s of IMU and LiDAR, twice
  std::string output;
  ASSERT_EQ(Decode(folder, "time", &output), 0) << output;
  ExpectSameAsSingleBag("time");
  EXPECT_NE(output.find("3 files (ROS 1 bag)"), std::string::npos) << output;
  EXPECT_NE(output.find(std::string(match[1]) + " duplicate messages dropped"), std::string::npos)
      << "expected " << match[1] << " duplicates: " << output;
  EXPECT_EQ(ProvenanceFiles("time"),
            (std::vector<std::string>{folder + "/run_0.bag", folder + "/run_1.bag",
                                      folder + "/run_2.bag"}));
}

TEST_F(DecodeSplitSequence, Ros1ImuAndLidarBagsDecodeLikeTheSingleBag) {
  const std::string folder = File("split_sensor");
  EXPECT_NE(Split(folder, "--by=sensor").find("duplicated 0"), std::string::npos);
  std::string output;
  ASSERT_EQ(Decode(folder, "sensor", &output), 0) << output;
  ExpectSameAsSingleBag("sensor");
  EXPECT_NE(output.find("0 duplicate messages dropped"), std::string::npos) << output;
  EXPECT_EQ(ProvenanceFiles("sensor"),
            (std::vector<std::string>{folder + "/imu.bag", folder + "/lidar.bag"}));
}

TEST_F(DecodeSplitSequence, Ros2McapAndDb3PartsDecodeLikeTheSingleBag) {
  if (const std::string missing = testing::Ros2OracleMissing(); !missing.empty()) {
    GTEST_SKIP() << missing;
  }
  SplitJsonl(File("part_0.jsonl"), File("part_1.jsonl"));
  std::string error;
  // A folder of two files in different formats: an MCAP and a .db3.
  const std::string folder = File("split_ros2");
  fs::create_directories(folder);
  ASSERT_TRUE(testing::WriteRos2Bag(folder + "/run_0.mcap",
                                    "--format=mcap --compression=zstd --messages=" +
                                        File("part_0.jsonl"),
                                    "", &error))
      << error;
  ASSERT_TRUE(testing::WriteRos2Bag(File("db3_part"),
                                    "--format=sqlite3 --messages=" + File("part_1.jsonl"), "",
                                    &error))
      << error;
  fs::rename(File("db3_part/db3_part_0.db3"), folder + "/run_1.db3");
  std::string output;
  ASSERT_EQ(Decode(folder, "ros2_parts", &output), 0) << output;
  ExpectSameAsSingleBag("ros2_parts");
  EXPECT_NE(output.find("2 files (MCAP, rosbag2 sqlite3)"), std::string::npos) << output;

  // A rosbag2 bag of storage mcap split into two files (metadata.yaml).
  const std::string bag = File("rosbag2_mcap");
  fs::create_directories(bag);
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(testing::WriteRos2Bag(bag + "/rosbag2_mcap_" + std::to_string(i) + ".mcap",
                                      "--format=mcap --compression=lz4 --messages=" +
                                          File("part_" + std::to_string(i) + ".jsonl"),
                                      "", &error))
        << error;
  }
  std::ofstream(bag + "/metadata.yaml")
      << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n"
         "  relative_file_paths:\n    - rosbag2_mcap_0.mcap\n    - rosbag2_mcap_1.mcap\n";
  ASSERT_EQ(Decode(bag, "rosbag2_mcap", &output), 0) << output;
  ExpectSameAsSingleBag("rosbag2_mcap");
  EXPECT_EQ(ProvenanceFiles("rosbag2_mcap"),
            (std::vector<std::string>{bag + "/rosbag2_mcap_0.mcap", bag + "/rosbag2_mcap_1.mcap"}));
}

TEST_F(DecodeSplitSequence, BadFileInTheFolderIsOneLineNamingIt) {
  const std::string folder = File("split_bad");
  Split(folder, "--by=sensor");
  // The LiDAR bag cut short in its header: not readable at all.
  fs::resize_file(folder + "/lidar.bag", 20);
  std::string output;
  EXPECT_EQ(Decode(folder, "bad", &output), 1) << output;
  EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
  EXPECT_NE(output.find(folder + "/lidar.bag"), std::string::npos) << output;
  EXPECT_TRUE(fs::is_empty(File("out_bad"))) << "output left behind";

  const std::string empty = File("no_bags");
  fs::create_directories(empty);
  std::ofstream(empty + "/notes.txt") << "not a bag\n";
  EXPECT_EQ(Decode(empty, "bad", &output), 1) << output;
  EXPECT_NE(output.find(empty + ": a folder with neither metadata.yaml nor bag files"),
            std::string::npos)
      << output;
  EXPECT_TRUE(fs::is_empty(File("out_bad"))) << "output left behind";
}

TEST_F(DecodeSplitSequence, OnlyATruncatedMcapSaysItWasSalvaged) {
  if (const std::string missing = testing::Ros2OracleMissing(); !missing.empty()) {
    GTEST_SKIP() << missing;
  }
  std::string error;
  const std::string bag = File("no_summary.mcap");
  ASSERT_TRUE(testing::WriteRos2Bag(bag, "--format=mcap --no-summary --messages=" + Jsonl(), "",
                                    &error))
      << error;
  std::string output;
  ASSERT_EQ(Decode(bag, "no_summary", &output), 0) << output;
  ExpectSameAsSingleBag("no_summary");
  EXPECT_EQ(output.find("salvaged"), std::string::npos) << output;

  fs::copy_file(bag, File("cut.mcap"));
  fs::resize_file(File("cut.mcap"), fs::file_size(bag) * 7 / 10);
  ASSERT_EQ(Decode(File("cut.mcap"), "cut", &output), 0) << output;
  EXPECT_NE(output.find("salvaged"), std::string::npos) << output;
  EXPECT_NE(output.find("the recording ends inside the"), std::string::npos) << output;
}

}  // namespace
}  // namespace tiltcal
