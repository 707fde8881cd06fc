// tiltcal_decode on Livox CustomMsg bags written by the reference libraries:
// ROS 1 by Debian's python3-rosbag (tests/oracle/write_livox_bag.py, the
// message class built by genpy from the livox_ros_driver definition), ROS 2
// (MCAP, rosbag2 sqlite3, big-endian CDR) by the npm libraries
// (tests/oracle/write_ros2_bags.mjs). Every decoded value is checked against
// what the oracle wrote, with the drop rule of stages/decode/livox_conversion.h
// applied here independently; bad Livox input is one error line naming the
// file and the message, exit 1, no output.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "common/io/record_stream.h"
#include "tests/bag/ros2/ros2_oracle.h"
#include "tests/testing/test_env.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {
namespace {

namespace fs = std::filesystem;
using testing::ToolPath;

// One CustomMsg as the oracle printed it.
struct ExpectedPoint {
  uint32_t offset_time;
  double x, y, z;
  int reflectivity, tag, line;
};
struct ExpectedMessage {
  int64_t stamp_ns = 0;
  int64_t timebase = 0;
  std::string frame;
  std::vector<ExpectedPoint> points;
};

std::vector<ExpectedMessage> ReadExpected(const std::string& path) {
  std::vector<ExpectedMessage> messages;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    if (line.rfind("msg ", 0) == 0) {
      std::string tag;
      int64_t sec, nsec, point_num, lidar_id;
      ExpectedMessage m;
      s >> tag >> sec >> nsec >> m.timebase >> point_num >> lidar_id >> m.frame;
      m.stamp_ns = sec * 1000000000 + nsec;
      messages.push_back(m);
      continue;
    }
    ExpectedPoint p;
    std::string x, y, z;
    s >> p.offset_time >> x >> y >> z >> p.reflectivity >> p.tag >> p.line;
    p.x = std::strtod(x.c_str(), nullptr);
    p.y = std::strtod(y.c_str(), nullptr);
    p.z = std::strtod(z.c_str(), nullptr);
    messages.back().points.push_back(p);
  }
  return messages;
}

// Runs tiltcal_decode; returns its exit status.
int Decode(const std::string& bag, const std::string& out_dir, const std::string& params,
           std::string* output) {
  fs::create_directories(out_dir);
  return testing::RunCommand(ToolPath("tiltcal_decode") + " --bag='" + bag + "'" +
                                 (params.empty() ? "" : " --params=" + params) + " --out_imu=" +
                                 out_dir + "/imu.binpb --out_scans=" + out_dir +
                                 "/scans.binpb.lz4 2>&1",
                             output);
}

// The default params with each `replacements` pair (a line of the defaults,
// its replacement) applied.
std::string WriteParams(const testing::TempDir& dir, const std::string& name,
                        const std::vector<std::pair<std::string, std::string>>& replacements) {
  std::ifstream in(testing::SourceDir() + "/stages/decode/default_params.txtpb");
  std::stringstream text;
  text << in.rdbuf();
  std::string params = text.str();
  for (const auto& [from, to] : replacements) {
    const size_t at = params.find(from);
    EXPECT_NE(at, std::string::npos) << "'" << from << "' not in the default params";
    if (at != std::string::npos) params.replace(at, from.size(), to);
  }
  std::ofstream(dir.File(name)) << params;
  return dir.File(name);
}

std::vector<proto::Scan> ReadScans(const std::string& path) {
  std::vector<proto::Scan> scans;
  const Status status = ReadAllRecords<proto::Scan>(path, &scans);
  EXPECT_TRUE(status.ok()) << status.message();
  return scans;
}

// Checks every scan against the oracle's messages with the drop rule:
// NaN/Inf coordinate, then range 0 or below min_range_m, then tag & mask.
void ExpectScansMatch(const std::vector<ExpectedMessage>& expected,
                      const std::vector<proto::Scan>& scans, double min_range_m,
                      uint32_t noise_mask, const std::string& label) {
  ASSERT_EQ(scans.size(), expected.size()) << label;
  int64_t total_noise = 0;
  for (size_t k = 0; k < scans.size(); ++k) {
    const ExpectedMessage& m = expected[k];
    const proto::Scan& scan = scans[k];
    SCOPED_TRACE(label + " scan " + std::to_string(k));
    EXPECT_EQ(scan.stamp_ns(), m.stamp_ns);
    EXPECT_EQ(scan.frame_id(), m.frame);
    EXPECT_EQ(scan.time_source(), proto::POINT_TIME_LIVOX_CUSTOM_MSG);
    uint32_t invalid = 0, too_close = 0, noise = 0;
    int kept = 0;
    for (const ExpectedPoint& p : m.points) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        ++invalid;
        continue;
      }
      const double range2 = p.x * p.x + p.y * p.y + p.z * p.z;
      if (range2 == 0.0 || range2 < min_range_m * min_range_m) {
        ++too_close;
        continue;
      }
      if ((p.tag & noise_mask) != 0) {
        ++noise;
        continue;
      }
      ASSERT_LT(kept, scan.x_size());
      EXPECT_EQ(scan.x(kept), static_cast<float>(p.x));
      EXPECT_EQ(scan.y(kept), static_cast<float>(p.y));
      EXPECT_EQ(scan.z(kept), static_cast<float>(p.z));
      EXPECT_EQ(scan.intensity(kept), static_cast<float>(p.reflectivity));
      EXPECT_EQ(scan.ring(kept), static_cast<uint32_t>(p.line));
      EXPECT_EQ(scan.time_offset_ns(kept), m.timebase + p.offset_time - m.stamp_ns);
      ++kept;
    }
    EXPECT_EQ(scan.x_size(), kept);
    EXPECT_EQ(scan.ring_size(), kept);
    EXPECT_EQ(scan.num_dropped_invalid(), invalid);
    EXPECT_EQ(scan.num_dropped_zero_range(), too_close);
    EXPECT_EQ(scan.num_dropped_noise_tag(), noise);
    total_noise += noise;
  }
  if (noise_mask != 0) {
    EXPECT_GT(total_noise, 0) << label << ": the oracle wrote no noise tag";
  }
}

class DecodeLivox : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!testing::HaveRosbagPython()) GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag";
    ASSERT_TRUE(testing::FileExists(ToolPath("tiltcal_decode"))) << "build tiltcal_decode first";
  }
  // Writes the oracle bag; returns its path (the expected values in NAME.txt).
  std::string WriteBag(const std::string& name, const std::string& args) {
    const std::string bag = dir_.File(name + ".bag");
    std::string output;
    EXPECT_EQ(testing::RunCommand(std::string(testing::kDebianPython) + " " +
                                      testing::SourceDir() + "/tests/oracle/write_livox_bag.py " +
                                      bag + " " + dir_.File(name + ".txt") + " " + args + " 2>&1",
                                  &output),
              0)
        << output;
    return bag;
  }
  testing::TempDir dir_;
};

TEST_F(DecodeLivox, Ros1BagsOfBothDriversDecodeToWhatTheOracleWrote) {
  for (const char* type : {"livox_ros_driver/CustomMsg", "livox_ros_driver2/CustomMsg"}) {
    const std::string name = std::string(type).substr(0, std::string(type).find('/'));
    const std::string bag = WriteBag(name, std::string("--type=") + type);
    const std::vector<ExpectedMessage> expected = ReadExpected(dir_.File(name + ".txt"));
    ASSERT_EQ(expected.size(), 4u);
    std::string output;
    ASSERT_EQ(Decode(bag, dir_.File("out_" + name), "", &output), 0) << output;
    EXPECT_NE(output.find("tagged as noise"), std::string::npos) << output;
    ExpectScansMatch(expected, ReadScans(dir_.File("out_" + name + "/scans.binpb.lz4")), 0.5,
                     0x0F, type);
    // The Livox IMU publishes g: detected and converted as for any IMU.
    EXPECT_NE(output.find("accelerometer in g, detected"), std::string::npos) << output;
  }
  // Another mask and minimum range: only the return-number bits drop points.
  const std::string params =
      WriteParams(dir_, "mask.txtpb",
                  {{"min_range_m: 0.5", "min_range_m: 2"},
                   {"noise_tag_mask: 15", "noise_tag_mask: 48"}});
  std::string output;
  ASSERT_EQ(Decode(dir_.File("livox_ros_driver.bag"), dir_.File("out_mask"), params, &output), 0)
      << output;
  ExpectScansMatch(ReadExpected(dir_.File("livox_ros_driver.txt")),
                   ReadScans(dir_.File("out_mask/scans.binpb.lz4")), 2.0, 0x30, "mask 0x30");
}

TEST_F(DecodeLivox, Ros2McapSqliteAndBigEndianDecodeAsTheRos1Bag) {
  if (const std::string missing = testing::Ros2OracleMissing(); !missing.empty()) {
    GTEST_SKIP() << missing;
  }
  const std::string bag = WriteBag("ros1", "");
  std::string output;
  ASSERT_EQ(Decode(bag, dir_.File("out_ros1"), "", &output), 0) << output;
  const std::vector<proto::Scan> reference = ReadScans(dir_.File("out_ros1/scans.binpb.lz4"));
  ExpectScansMatch(ReadExpected(dir_.File("ros1.txt")), reference, 0.5, 0x0F, "ros1");
  const std::string convert = std::string(testing::kDebianPython) + " " + testing::SourceDir() +
                              "/tests/oracle/ros1_bag_to_ros2_jsonl.py " + bag;
  ASSERT_EQ(testing::RunCommand(convert + " > " + dir_.File("driver2.jsonl")), 0);
  ASSERT_EQ(testing::RunCommand(convert + " --livox_type=livox_interfaces/msg/CustomMsg > " +
                                dir_.File("interfaces.jsonl")),
            0);
  struct Case {
    const char* name;
    const char* jsonl;
    const char* args;
  };
  const Case cases[] = {
      {"run.mcap", "driver2.jsonl", "--format=mcap --compression=zstd"},
      {"run_be.mcap", "driver2.jsonl", "--format=mcap --big-endian"},
      {"run_sqlite3", "interfaces.jsonl", "--format=sqlite3"},
  };
  for (const Case& c : cases) {
    std::string error;
    ASSERT_TRUE(testing::WriteRos2Bag(dir_.File(c.name),
                                      std::string(c.args) + " --messages=" + dir_.File(c.jsonl),
                                      "", &error))
        << error;
    ASSERT_EQ(Decode(dir_.File(c.name), dir_.File(std::string("out_") + c.name), "", &output), 0)
        << c.name << ": " << output;
    const std::vector<proto::Scan> scans =
        ReadScans(dir_.File(std::string("out_") + c.name + "/scans.binpb.lz4"));
    ASSERT_EQ(scans.size(), reference.size()) << c.name;
    for (size_t k = 0; k < scans.size(); ++k) {
      EXPECT_EQ(scans[k].SerializeAsString(), reference[k].SerializeAsString())
          << c.name << " scan " << k;
    }
  }
}

class DecodeLivoxBadInput : public DecodeLivox {
 protected:
  // One line naming every string of `must_contain`, exit 1, nothing in out_bad/.
  void ExpectCleanFailure(const std::string& bag, const std::vector<std::string>& must_contain,
                          const std::string& params = "") {
    std::string output;
    EXPECT_EQ(Decode(bag, dir_.File("out_bad"), params, &output), 1) << output;
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    for (const std::string& s : must_contain) {
      EXPECT_NE(output.find(s), std::string::npos) << "'" << s << "' not in: " << output;
    }
    EXPECT_TRUE(fs::is_empty(dir_.File("out_bad"))) << "output left behind";
  }
};

TEST_F(DecodeLivoxBadInput, PointNumTruncationDefinitionAndClockAreOneErrorLine) {
  const std::string topic = "topic '/livox/lidar' message ";
  ExpectCleanFailure(WriteBag("point_num", "--bad=point_num"),
                     {dir_.File("point_num.bag"), topic + "1", "livox_ros_driver/CustomMsg",
                      "point_num is 501 but the points array holds 500 points"});
  ExpectCleanFailure(WriteBag("truncated", "--bad=truncated"),
                     {dir_.File("truncated.bag"), topic + "1", "runs past its record: points"});
  // A CustomPoint without `line` (another definition under the same name).
  ExpectCleanFailure(WriteBag("definition", "--bad=definition"),
                     {dir_.File("definition.bag"), topic + "0", "runs past its record: points"});
  // Message 2's timebase is 3 ms before its stamp.
  const std::string params =
      WriteParams(dir_, "strict.txtpb",
                  {{"max_timebase_stamp_difference_s: 0.1", "max_timebase_stamp_difference_s: 0.001"}});
  ExpectCleanFailure(WriteBag("clock", ""),
                     {dir_.File("clock.bag"), topic + "2", "-0.003000 s from header.stamp",
                      "livox.max_timebase_stamp_difference_s"},
                     params);
}

TEST_F(DecodeLivoxBadInput, NoiseTagMaskOutOfRangeIsAnError) {
  const std::string params =
      WriteParams(dir_, "bad_mask.txtpb", {{"noise_tag_mask: 15", "noise_tag_mask: 256"}});
  ExpectCleanFailure(WriteBag("ok", ""), {"livox.noise_tag_mask"}, params);
}

}  // namespace
}  // namespace tiltcal
