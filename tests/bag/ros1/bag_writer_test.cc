// The ROS1 bag writer, checked against the real ROS library: bags written
// with each compression are read by Debian's python3-rosbag and every
// message (raw bytes CRC, record time, header) must match what was written.
#include "bag/ros1/bag_writer.h"

#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros1/message_encoding.h"
#include "common/io/atomic_file.h"
#include "tests/bag/ros1/rosbag_oracle.h"
#include "tests/testing/random_vector.h"
#include "tests/testing/test_env.h"

namespace tiltcal::ros1 {
namespace {

using testing::BagDump;
using testing::Crc32;
using testing::DumpBagWithRosbag;
using tiltcal::testing::TempDir;

struct Written {
  std::string topic;
  int64_t record_ns;
  int64_t stamp_ns;
  uint32_t seq;
  std::string frame_id;
  std::string bytes;
};

// Writes a bag with an IMU topic, a topic without a leading slash and a
// PointCloud2 topic larger than the chunk threshold; returns what was written.
std::vector<Written> WriteTestBag(const std::string& path, ChunkCompression compression,
                                  uint32_t chunk_threshold, unsigned compression_threads = 1) {
  BagWriter writer;
  EXPECT_TRUE(writer.Open(path, compression, chunk_threshold, compression_threads).ok());
  const MessageType& imu = ImuMessageType();
  const MessageType& cloud = PointCloud2MessageType();
  const uint32_t c_imu = writer.AddConnection("/imu/data", imu.type, imu.md5sum, imu.definition);
  const uint32_t c_raw = writer.AddConnection("imu_raw", imu.type, imu.md5sum, imu.definition);
  const uint32_t c_cloud =
      writer.AddConnection("/points", cloud.type, cloud.md5sum, cloud.definition);
  std::mt19937_64 rng(42);
  std::normal_distribution<double> gaussian;
  std::vector<Written> written;
  const int64_t t0 = 1600000000123456789LL;
  for (int i = 0; i < 300; ++i) {
    const int64_t stamp = t0 + i * 5000000LL;
    Written w{i % 3 == 2 ? "imu_raw" : "/imu/data", stamp + 1000000, stamp,
              static_cast<uint32_t>(i), "imu_link", ""};
    const Eigen::Vector3d omega = tiltcal::testing::RandomVector3(gaussian, rng);
    const Eigen::Vector3d accel =
        tiltcal::testing::RandomVector3(gaussian, rng) + Eigen::Vector3d(0.0, 0.0, 9.81);
    EXPECT_TRUE(SerializeImu(w.seq, stamp, w.frame_id, omega, accel, 1e-6, 1e-4, &w.bytes));
    EXPECT_TRUE(writer.Write(i % 3 == 2 ? c_raw : c_imu, w.record_ns, w.bytes).ok());
    written.push_back(w);
    if (i % 50 == 7) {
      // A cloud of random bytes (5000 points x 16 bytes): layout does not matter here.
      Written c{"/points", stamp + 2000000, stamp, static_cast<uint32_t>(i / 50), "lidar", ""};
      std::string data(5000 * 16, '\0');
      for (char& b : data) b = static_cast<char>(rng() & 0xFF);
      const std::vector<PointField> fields = {{"x", 0, kFloat32, 1}, {"y", 4, kFloat32, 1},
                                              {"z", 8, kFloat32, 1}, {"t", 12, kUint32, 1}};
      EXPECT_TRUE(SerializePointCloud2(c.seq, stamp, c.frame_id, 1, 5000, fields, 16, data, true,
                                       &c.bytes));
      EXPECT_TRUE(writer.Write(c_cloud, c.record_ns, c.bytes).ok());
      written.push_back(c);
    }
  }
  EXPECT_TRUE(writer.Close().ok());
  return written;
}

class BagWriterRosbagTest : public ::testing::TestWithParam<ChunkCompression> {};

TEST_P(BagWriterRosbagTest, RealRosLibraryReadsEveryMessage) {
  if (!tiltcal::testing::HaveRosbagPython()) {
    GTEST_SKIP() << "Debian python3-rosbag (/usr/bin/python3) is not installed";
  }
  TempDir dir;
  const std::string bag = dir.File("writer.bag");
  const std::vector<Written> written = WriteTestBag(bag, GetParam(), 4096, 3);
  BagDump dump;
  std::string error;
  ASSERT_TRUE(DumpBagWithRosbag(bag, dir.File("dump.txt"), {}, &dump, &error)) << error;
  EXPECT_EQ(dump.compression, ChunkCompressionName(GetParam()));
  for (const std::string topic : {"/imu/data", "imu_raw", "/points"}) {
    std::vector<const Written*> expected;
    for (const Written& w : written) {
      if (w.topic == topic) expected.push_back(&w);
    }
    const auto read = dump.Topic(topic);
    ASSERT_EQ(read.size(), expected.size()) << topic;
    for (size_t i = 0; i < read.size(); ++i) {
      SCOPED_TRACE(topic + " message " + std::to_string(i));
      EXPECT_EQ(read[i]->record_ns, expected[i]->record_ns);
      EXPECT_EQ(read[i]->stamp_ns, expected[i]->stamp_ns);
      EXPECT_EQ(read[i]->seq, expected[i]->seq);
      EXPECT_EQ(read[i]->frame_id, expected[i]->frame_id);
      EXPECT_EQ(read[i]->size, expected[i]->bytes.size());
      EXPECT_EQ(read[i]->crc32, Crc32(expected[i]->bytes.data(), expected[i]->bytes.size()));
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, BagWriterRosbagTest,
                         ::testing::Values(ChunkCompression::kNone, ChunkCompression::kBz2,
                                           ChunkCompression::kLz4),
                         [](const auto& info) {
                           return std::string(ChunkCompressionName(info.param));
                         });

TEST(BagWriterTest, LayoutOfTheFileStart) {
  TempDir dir;
  const std::string bag = dir.File("layout.bag");
  WriteTestBag(bag, ChunkCompression::kLz4, 1 << 20);
  std::string bytes;
  ASSERT_TRUE(ReadFileToString(bag, &bytes).ok());
  ASSERT_GT(bytes.size(), 4200u);
  EXPECT_EQ(bytes.substr(0, 13), "#ROSBAG V2.0\n");
  uint32_t header_len = 0, data_len = 0;
  std::memcpy(&header_len, bytes.data() + 13, 4);
  std::memcpy(&data_len, bytes.data() + 17 + header_len, 4);
  EXPECT_EQ(header_len + data_len, 4096u);
  // The first chunk starts at 13 + 4 + 4096 + 4 = 4117 and holds one lz4
  // frame with roslz4's options (FLG 0x64, BD 0x60).
  uint32_t chunk_header_len = 0;
  std::memcpy(&chunk_header_len, bytes.data() + 4117, 4);
  const size_t data_start = 4117 + 4 + chunk_header_len + 4;
  const unsigned char* d = reinterpret_cast<const unsigned char*>(bytes.data()) + data_start;
  EXPECT_EQ(d[0], 0x04);
  EXPECT_EQ(d[1], 0x22);
  EXPECT_EQ(d[2], 0x4D);
  EXPECT_EQ(d[3], 0x18);
  EXPECT_EQ(d[4], 0x64);
  EXPECT_EQ(d[5], 0x60);
}

TEST(BagWriterTest, CompressionThreadsDoNotChangeTheBytes) {
  TempDir dir;
  for (const auto c : {ChunkCompression::kBz2, ChunkCompression::kLz4}) {
    WriteTestBag(dir.File("one.bag"), c, 4096, 1);
    WriteTestBag(dir.File("four.bag"), c, 4096, 4);
    std::string one, four;
    ASSERT_TRUE(ReadFileToString(dir.File("one.bag"), &one).ok());
    ASSERT_TRUE(ReadFileToString(dir.File("four.bag"), &four).ok());
    EXPECT_TRUE(one == four) << ChunkCompressionName(c);
  }
}

TEST(BagWriterTest, NothingIsLeftWithoutClose) {
  TempDir dir;
  const std::string bag = dir.File("unfinished.bag");
  {
    BagWriter writer;
    ASSERT_TRUE(writer.Open(bag, ChunkCompression::kNone, 4096).ok());
    const MessageType& imu = ImuMessageType();
    const uint32_t c = writer.AddConnection("/imu", imu.type, imu.md5sum, imu.definition);
    std::string msg;
    ASSERT_TRUE(SerializeImu(0, 1000000000, "imu", Eigen::Vector3d::Zero(),
                             Eigen::Vector3d::Zero(), 0, 0, &msg));
    ASSERT_TRUE(writer.Write(c, 1000000000, msg).ok());
  }
  EXPECT_FALSE(tiltcal::testing::FileExists(bag));
}

TEST(BagWriterTest, RejectsTimesOutsideRosTime) {
  TempDir dir;
  BagWriter writer;
  ASSERT_TRUE(writer.Open(dir.File("bad.bag"), ChunkCompression::kNone, 4096).ok());
  const MessageType& imu = ImuMessageType();
  const uint32_t c = writer.AddConnection("/imu", imu.type, imu.md5sum, imu.definition);
  EXPECT_FALSE(writer.Write(c, -5, "x").ok());
  EXPECT_FALSE(writer.Write(c + 7, 5, "x").ok());
}

}  // namespace
}  // namespace tiltcal::ros1
