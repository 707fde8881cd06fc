#include "bag/ros1/messages.h"

#include <gtest/gtest.h>

namespace tiltcal::ros1 {
namespace {

void AppendString(std::string* out, const std::string& s) {
  AppendU32Le(out, static_cast<uint32_t>(s.size()));
  *out += s;
}

std::string SerializeImu(const std::string& frame, double base) {
  std::string b;
  AppendU32Le(&b, 42);          // seq
  AppendU32Le(&b, 1700000000);  // stamp.sec
  AppendU32Le(&b, 5);           // stamp.nsec
  AppendString(&b, frame);
  for (int i = 0; i < 37; ++i) AppendLe<double>(&b, base + i);
  return b;
}

TEST(Ros1Messages, DecodesImuFields) {
  const std::string bytes = SerializeImu("imu_link", 0.5);
  EXPECT_EQ(bytes.size(), 312u + 8u);  // 312 + |frame_id|
  ImuMessage imu;
  Status status = DecodeImu(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), &imu);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(imu.header.seq, 42u);
  EXPECT_EQ(RosTimeToNs(imu.header.stamp), 1700000000000000005LL);
  EXPECT_EQ(imu.header.frame_id, "imu_link");
  EXPECT_EQ(imu.orientation[0], 0.5);
  EXPECT_EQ(imu.orientation[3], 3.5);
  EXPECT_EQ(imu.orientation_covariance[8], 12.5);
  EXPECT_EQ(imu.angular_velocity[0], 13.5);
  EXPECT_EQ(imu.angular_velocity[2], 15.5);
  EXPECT_EQ(imu.angular_velocity_covariance[0], 16.5);
  EXPECT_EQ(imu.linear_acceleration[0], 25.5);
  EXPECT_EQ(imu.linear_acceleration[2], 27.5);
  EXPECT_EQ(imu.linear_acceleration_covariance[8], 36.5);
}

TEST(Ros1Messages, TruncatedOrOversizedImuIsAnError) {
  const std::string bytes = SerializeImu("base_link", 1.0);
  ImuMessage imu;
  for (size_t n = 0; n < bytes.size(); n += 7) {
    Status status = DecodeImu(reinterpret_cast<const uint8_t*>(bytes.data()), n, &imu);
    ASSERT_FALSE(status.ok()) << n;
    EXPECT_NE(status.message().find("runs past its record"), std::string::npos);
  }
  // A frame_id length larger than the message.
  std::string bad = bytes;
  bad[12] = '\xff';
  EXPECT_FALSE(DecodeImu(reinterpret_cast<const uint8_t*>(bad.data()), bad.size(), &imu).ok());
  const std::string longer = bytes + "x";
  Status status =
      DecodeImu(reinterpret_cast<const uint8_t*>(longer.data()), longer.size(), &imu);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("1 bytes after the end"), std::string::npos);
}

std::string SerializeCloud() {
  std::string b;
  AppendU32Le(&b, 1);
  AppendU32Le(&b, 10);
  AppendU32Le(&b, 20);
  AppendString(&b, "velodyne");
  AppendU32Le(&b, 2);  // height
  AppendU32Le(&b, 3);  // width
  AppendU32Le(&b, 2);  // fields
  AppendString(&b, "x");
  AppendU32Le(&b, 0);
  b += static_cast<char>(kFloat32);
  AppendU32Le(&b, 1);
  AppendString(&b, "ring");
  AppendU32Le(&b, 4);
  b += static_cast<char>(kUint16);
  AppendU32Le(&b, 1);
  b += '\x01';  // is_bigendian
  AppendU32Le(&b, 6);   // point_step
  AppendU32Le(&b, 20);  // row_step
  AppendString(&b, std::string(40, 'd'));
  b += '\x00';  // is_dense
  return b;
}

TEST(Ros1Messages, DecodesPointCloud2Layout) {
  const std::string b = SerializeCloud();
  PointCloud2View cloud;
  Status status =
      DecodePointCloud2(reinterpret_cast<const uint8_t*>(b.data()), b.size(), &cloud);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(cloud.header.frame_id, "velodyne");
  EXPECT_EQ(cloud.height, 2u);
  EXPECT_EQ(cloud.width, 3u);
  ASSERT_EQ(cloud.fields.size(), 2u);
  EXPECT_EQ(cloud.fields[1].name, "ring");
  EXPECT_EQ(cloud.fields[1].offset, 4u);
  EXPECT_EQ(cloud.fields[1].datatype, kUint16);
  EXPECT_TRUE(cloud.is_bigendian);
  EXPECT_EQ(cloud.point_step, 6u);
  EXPECT_EQ(cloud.row_step, 20u);
  EXPECT_EQ(cloud.data_size, 40u);
  EXPECT_EQ(cloud.data, reinterpret_cast<const uint8_t*>(b.data()) + b.size() - 41);
  EXPECT_FALSE(cloud.is_dense);
  for (size_t n = 0; n < b.size(); ++n) {
    ASSERT_FALSE(DecodePointCloud2(reinterpret_cast<const uint8_t*>(b.data()), n, &cloud).ok())
        << n;
  }
}

// Every single corrupted byte of a cloud message decodes and converts to a
// result or an error; never a crash or an out-of-bounds read (checked by the
// TILTCAL_SANITIZE build).
std::string SerializeXyzCloud() {
  std::string b;
  AppendU32Le(&b, 1);
  AppendU32Le(&b, 10);
  AppendU32Le(&b, 20);
  AppendString(&b, "l");
  AppendU32Le(&b, 2);  // height
  AppendU32Le(&b, 3);  // width
  const std::pair<const char*, uint8_t> fields[] = {
      {"x", kFloat32}, {"y", kFloat32}, {"z", kFloat32}, {"time", kFloat32}};
  AppendU32Le(&b, 4);
  uint32_t offset = 0;
  for (const auto& [name, type] : fields) {
    AppendString(&b, name);
    AppendU32Le(&b, offset);
    b += static_cast<char>(type);
    AppendU32Le(&b, 1);
    offset += 4;
  }
  b += '\x00';
  AppendU32Le(&b, 16);  // point_step
  AppendU32Le(&b, 50);  // row_step: 2 padding bytes
  std::string data;
  for (int i = 0; i < 25; ++i) AppendLe<float>(&data, 0.05f * i - 0.3f);
  AppendString(&b, data);
  b += '\x01';
  return b;
}

TEST(Ros1Messages, CorruptedCloudsNeverCrash) {
  const std::string good = SerializeXyzCloud();
  for (size_t i = 0; i < good.size(); ++i) {
    for (uint8_t flip : {0x01, 0x80, 0xFF}) {
      std::string b = good;
      b[i] = static_cast<char>(b[i] ^ flip);
      const auto* bytes = reinterpret_cast<const uint8_t*>(b.data());
      PointCloud2View cloud;
      if (!DecodePointCloud2(bytes, b.size(), &cloud).ok()) continue;
      // A decoded cloud's data lies inside the message.
      EXPECT_GE(cloud.data, bytes);
      EXPECT_LE(cloud.data + cloud.data_size, bytes + b.size());
    }
  }
}

}  // namespace
}  // namespace tiltcal::ros1
