// The real public ROS1 bags of ../shared/fixtures/bags/ros1, read by our
// reader and compared value by value with what Debian's python rosbag
// library reads (tests/oracle/rosbag_dump.py).
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros1/bag_reader.h"
#include "bag/ros1/messages.h"
#include "stages/decode/point_cloud_conversion.h"
#include "tests/bag/ros1/bag_test_util.h"
#include "tests/testing/test_env.h"

namespace tiltcal {
namespace {

using testing::OracleDump;
using testing::SplitWords;

std::string FixtureBag(const std::string& name) {
  const std::string dir = testing::SharedFixturesDir();
  if (dir.empty()) return "";
  const std::string path = dir + "/bags/ros1/" + name;
  return testing::FileExists(path) ? path : "";
}

#define REQUIRE_FIXTURE(var, name)                                                      \
  const std::string var = FixtureBag(name);                                             \
  if (var.empty()) {                                                                    \
    GTEST_SKIP() << "fixture bags/ros1/" << name                                        \
                 << " not found (../shared/fixtures absent); skipping";                 \
  }

// Skips when the oracle could not run because python3-rosbag is missing.
#define REQUIRE_ORACLE(lines)                                                           \
  if ((lines).empty() && !testing::HaveRosbagPython()) {                                \
    GTEST_SKIP() << "/usr/bin/python3 cannot import rosbag (Debian python3-rosbag); "   \
                    "skipping the oracle comparison";                                   \
  }

struct RawMessage {
  std::string topic;
  int64_t time_ns;
  std::string bytes;
};

std::vector<RawMessage> ReadAll(const std::string& path, const std::string& topic = "") {
  ros1::BagReader reader;
  Status status = reader.Open(path);
  EXPECT_TRUE(status.ok()) << status.message();
  std::vector<RawMessage> out;
  ros1::ReadOptions options;
  if (!topic.empty()) options.topics = {topic};
  options.chunk_cache_size = 2;
  status = reader.ReadMessages(options, [&](const ros1::MessageView& m) {
    out.push_back({m.connection->topic, m.time_ns,
                   std::string(reinterpret_cast<const char*>(m.data), m.size)});
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
  return out;
}

TEST(Ros1FixtureBags, Bz2AndLz4VersionsHoldIdenticalMessages) {
  REQUIRE_FIXTURE(bz2, "rosbagjs_example-bz2.bag");
  REQUIRE_FIXTURE(lz4, "rosbagjs_example-lz4.bag");
  const std::vector<RawMessage> a = ReadAll(bz2);
  const std::vector<RawMessage> b = ReadAll(lz4);
  ASSERT_GT(a.size(), 1000u);
  ASSERT_EQ(a.size(), b.size());
  std::map<std::string, int> per_topic;
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].topic, b[i].topic) << "message " << i;
    ASSERT_EQ(a[i].time_ns, b[i].time_ns) << "message " << i;
    ASSERT_EQ(a[i].bytes, b[i].bytes) << "message " << i;
    if (i > 0) {
      ASSERT_LE(a[i - 1].time_ns, a[i].time_ns) << "message " << i;
    }
    ++per_topic[a[i].topic];
  }
  // Per-topic counts agree with the real rosbag library.
  for (const auto& [topic, count] : per_topic) {
    std::string log;
    const std::vector<std::string> oracle = OracleDump(lz4, topic, &log);
    REQUIRE_ORACLE(oracle);
    EXPECT_EQ(static_cast<int>(oracle.size()), count) << topic << log;
  }
}

TEST(Ros1FixtureBags, UnsortedChunksComeOutInTimeOrder) {
  REQUIRE_FIXTURE(path, "rosbagjs_example-unsorted-chunks.bag");
  const std::vector<RawMessage> messages = ReadAll(path);
  ASSERT_EQ(messages.size(), 3u);
  for (size_t i = 1; i < messages.size(); ++i) {
    EXPECT_LT(messages[i - 1].time_ns, messages[i].time_ns);
  }
  EXPECT_EQ(messages[0].time_ns, 1000000000);  // the chunk stored last holds the 1 s message
  EXPECT_EQ(messages[0].topic, "foo");
  // python rosbag yields them in file order; the set of record times agrees.
  std::string log;
  const std::vector<std::string> lines = OracleDump(path, "foo", &log);
  REQUIRE_ORACLE(lines);
  std::vector<int64_t> oracle;
  for (const std::string& line : lines) {
    oracle.push_back(std::stoll(SplitWords(line)[1]));
  }
  std::sort(oracle.begin(), oracle.end());
  ASSERT_EQ(oracle.size(), 3u) << log;
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(oracle[i], messages[i].time_ns);
}

TEST(Ros1FixtureBags, NoMessagesBagOpensEmpty) {
  REQUIRE_FIXTURE(path, "rosbagjs_no-messages.bag");
  ros1::BagReader reader;
  Status status = reader.Open(path);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(reader.indexed());
  EXPECT_TRUE(reader.connections().empty());
  EXPECT_EQ(reader.TotalMessageCount(), 0);
  int64_t start = 0, end = 0;
  EXPECT_FALSE(reader.TimeRange(&start, &end));
  int calls = 0;
  status = reader.ReadMessages({}, [&](const ros1::MessageView&) {
    ++calls;
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(calls, 0);
}

// Every Imu value of `topic` equals what python rosbag reads.
void CompareImuWithOracle(const std::string& path, const std::string& topic,
                          size_t expected_count, int64_t expected_first_stamp_ns,
                          const std::string& expected_frame) {
  ros1::BagReader reader;
  Status status = reader.Open(path);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(reader.TopicsOfType(ros1::kImuType), std::vector<std::string>{topic});
  std::vector<std::pair<int64_t, ros1::ImuMessage>> ours;
  status = reader.ReadMessages({{topic}}, [&](const ros1::MessageView& m) {
    ros1::ImuMessage imu;
    TILTCAL_RETURN_IF_ERROR(ros1::DecodeImu(m.data, m.size, &imu));
    ours.emplace_back(m.time_ns, imu);
    return Status::Ok();
  });
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(ours.size(), expected_count);
  EXPECT_EQ(ros1::RosTimeToNs(ours[0].second.header.stamp), expected_first_stamp_ns);
  EXPECT_EQ(ours[0].second.header.frame_id, expected_frame);

  std::string log;
  const std::vector<std::string> oracle = OracleDump(path, topic, &log);
  REQUIRE_ORACLE(oracle);
  ASSERT_EQ(oracle.size(), ours.size()) << log;
  for (size_t i = 0; i < oracle.size(); ++i) {
    const std::vector<std::string> w = SplitWords(oracle[i]);
    ASSERT_EQ(w.size(), 14u) << oracle[i];
    const ros1::ImuMessage& imu = ours[i].second;
    ASSERT_EQ(std::stoll(w[1]), ours[i].first) << "message " << i;
    ASSERT_EQ(std::stoll(w[2]), ros1::RosTimeToNs(imu.header.stamp)) << "message " << i;
    ASSERT_EQ(w[3], "frame=" + imu.header.frame_id) << "message " << i;
    const double values[10] = {imu.orientation[0],         imu.orientation[1],
                               imu.orientation[2],         imu.orientation[3],
                               imu.angular_velocity[0],    imu.angular_velocity[1],
                               imu.angular_velocity[2],    imu.linear_acceleration[0],
                               imu.linear_acceleration[1], imu.linear_acceleration[2]};
    for (int k = 0; k < 10; ++k) {
      ASSERT_EQ(std::strtod(w[4 + k].c_str(), nullptr), values[k])
          << "message " << i << " value " << k;
    }
  }
}

TEST(Ros1FixtureBags, RobotLocalizationImuMatchesRosbag) {
  REQUIRE_FIXTURE(path, "robot_localization_test2_bz2_imu.bag");
  // 3061 messages, first stamp 47.58 s (sim time), frame base_link (fixture README).
  CompareImuWithOracle(path, "/imu/data", 3061, 47580000000, "base_link");
}

TEST(Ros1FixtureBags, CartographerImuMatchesRosbag) {
  REQUIRE_FIXTURE(path, "cartographer_b0_tiny_bz2_imu.bag");
  // Topic without a leading slash; first stamp 1405946573.704504900 s.
  CompareImuWithOracle(path, "imu", 1243, 1405946573704504900, "imu_link");
}

// Converts every cloud of `topic` (min_range 0) and compares each kept point
// with python's read_points of the same message.
void CompareCloudsWithOracle(const std::string& path, const std::string& topic,
                             size_t expected_clouds, uint32_t expected_point_step,
                             proto::PointTimeSource expected_source) {
  ros1::BagReader reader;
  Status status = reader.Open(path);
  ASSERT_TRUE(status.ok()) << status.message();
  std::vector<proto::Scan> scans;
  std::vector<ros1::PointCloud2View> layouts;
  status = reader.ReadMessages({{topic}}, [&](const ros1::MessageView& m) {
    ros1::PointCloud2View cloud;
    TILTCAL_RETURN_IF_ERROR(ros1::DecodePointCloud2(m.data, m.size, &cloud));
    proto::Scan scan;
    TILTCAL_RETURN_IF_ERROR(ConvertPointCloud2ToScan(cloud, PointConversionOptions{}, &scan));
    scan.set_record_stamp_ns(m.time_ns);
    cloud.data = nullptr;
    layouts.push_back(cloud);
    scans.push_back(std::move(scan));
    return Status::Ok();
  });
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(scans.size(), expected_clouds);
  for (const auto& layout : layouts) EXPECT_EQ(layout.point_step, expected_point_step);
  for (const auto& scan : scans) EXPECT_EQ(scan.time_source(), expected_source);

  std::string log;
  const std::vector<std::string> oracle = OracleDump(path, topic, &log);
  REQUIRE_ORACLE(oracle);
  ASSERT_FALSE(oracle.empty()) << log;
  size_t line = 0;
  for (size_t s = 0; s < scans.size(); ++s) {
    const proto::Scan& scan = scans[s];
    ASSERT_LT(line, oracle.size());
    const std::vector<std::string> head = SplitWords(oracle[line++]);
    ASSERT_EQ(head[0], "cloud");
    EXPECT_EQ(std::stoll(head[1]), scan.record_stamp_ns());
    const int64_t stamp_ns = std::stoll(head[2]);
    EXPECT_EQ(stamp_ns, scan.stamp_ns());
    EXPECT_EQ(head[3], "frame=" + scan.frame_id());
    const uint64_t num_points = std::stoull(head[4]) * std::stoull(head[5]);
    EXPECT_EQ(std::stoul(head[6]), layouts[s].point_step);
    std::vector<std::string> names;
    {
      std::string names_csv = head[8];
      size_t start = 0;
      while (start <= names_csv.size()) {
        const size_t comma = names_csv.find(',', start);
        names.push_back(names_csv.substr(start, comma - start));
        if (comma == std::string::npos) break;
        start = comma + 1;
      }
    }
    auto column = [&](const std::string& name) {
      for (size_t k = 0; k < names.size(); ++k) {
        if (names[k] == name) return static_cast<int>(k) + 1;
      }
      return -1;
    };
    const int cx = column("x"), cy = column("y"), cz = column("z");
    const int ci = column("intensity"), cring = column("laser_id");
    const int csec = column("time_sec"), cnsec = column("time_nsec");
    int kept = 0;
    uint32_t invalid = 0, zero = 0;
    for (uint64_t p = 0; p < num_points; ++p) {
      ASSERT_LT(line, oracle.size());
      const std::vector<std::string> w = SplitWords(oracle[line++]);
      ASSERT_EQ(w[0], "p");
      const float x = static_cast<float>(std::strtod(w[cx].c_str(), nullptr));
      const float y = static_cast<float>(std::strtod(w[cy].c_str(), nullptr));
      const float z = static_cast<float>(std::strtod(w[cz].c_str(), nullptr));
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        ++invalid;
        continue;
      }
      if (x == 0.0f && y == 0.0f && z == 0.0f) {
        ++zero;
        continue;
      }
      ASSERT_LT(kept, scan.x_size());
      ASSERT_EQ(scan.x(kept), x) << "cloud " << s << " point " << p;
      ASSERT_EQ(scan.y(kept), y) << "cloud " << s << " point " << p;
      ASSERT_EQ(scan.z(kept), z) << "cloud " << s << " point " << p;
      if (ci > 0) {
        ASSERT_EQ(scan.intensity(kept), static_cast<float>(std::strtod(w[ci].c_str(), nullptr)));
      } else {
        ASSERT_EQ(scan.intensity(kept), 0.0f);
      }
      if (cring > 0) {
        ASSERT_EQ(scan.ring(kept), std::stoul(w[cring]));
      } else {
        ASSERT_EQ(scan.ring_size(), 0);
      }
      if (csec > 0) {
        const int64_t t = std::stoll(w[csec]) * 1000000000 + std::stoll(w[cnsec]);
        ASSERT_EQ(scan.time_offset_ns(kept), t - stamp_ns) << "cloud " << s << " point " << p;
      } else {
        ASSERT_EQ(scan.time_offset_ns(kept), 0);
      }
      ++kept;
    }
    EXPECT_EQ(kept, scan.x_size());
    EXPECT_EQ(invalid, scan.num_dropped_invalid());
    EXPECT_EQ(zero, scan.num_dropped_zero_range());
  }
  EXPECT_EQ(line, oracle.size());
}

TEST(Ros1FixtureBags, EmbagPointCloud2MatchesRosbag) {
  REQUIRE_FIXTURE(path, "embag_test_lz4_pointcloud2.bag");
  // 5 clouds of 35707 points, point_step 32, per-point time_sec + time_nsec.
  CompareCloudsWithOracle(path, "/luminar_pointcloud", 5, 32, proto::POINT_TIME_SEC_NSEC);
}

TEST(Ros1FixtureBags, RosNumpyPointCloud2MatchesRosbag) {
  REQUIRE_FIXTURE(path, "ros_numpy_test_pointcloud2.bag");
  // x y z FLOAT32 + r g b UINT8: point_step 15 (unaligned), no time field.
  CompareCloudsWithOracle(path, "/pointcloud", 1, 15, proto::POINT_TIME_NONE);
}

TEST(Ros1FixtureBags, EmbagCloudsHaveTheDocumentedSize) {
  REQUIRE_FIXTURE(path, "embag_test_lz4_pointcloud2.bag");
  ros1::BagReader reader;
  ASSERT_TRUE(reader.Open(path).ok());
  EXPECT_EQ(reader.MessageCount("/luminar_pointcloud"), 5);
  Status status = reader.ReadMessages({{"/luminar_pointcloud"}}, [&](const ros1::MessageView& m) {
    ros1::PointCloud2View cloud;
    TILTCAL_RETURN_IF_ERROR(ros1::DecodePointCloud2(m.data, m.size, &cloud));
    if (m.sequence == 0) {
      EXPECT_EQ(cloud.width * cloud.height, 35707u);  // the first cloud
    }
    EXPECT_EQ(cloud.point_step, 32u);
    EXPECT_EQ(cloud.data_size, uint64_t{cloud.row_step} * cloud.height);
    return Status::Ok();
  });
  EXPECT_TRUE(status.ok()) << status.message();
}

}  // namespace
}  // namespace tiltcal
