#include "bag/ros2/cdr_reader.h"

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros2/messages.h"

namespace tiltcal::ros2 {
namespace {

// A minimal plain-CDR writer for hand-made payloads: values aligned to their
// size relative to byte 4 (after the encapsulation header).
class CdrBytes {
 public:
  explicit CdrBytes(bool big_endian) : big_endian_(big_endian) {
    bytes_ = {0, static_cast<uint8_t>(big_endian ? 0 : 1), 0, 0};
  }
  template <typename T>
  CdrBytes& Put(T v) {
    while ((bytes_.size() - 4) % sizeof(T) != 0) bytes_.push_back(0xAA);  // padding
    uint8_t b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big_endian_) std::reverse(b, b + sizeof(T));
    bytes_.insert(bytes_.end(), b, b + sizeof(T));
    return *this;
  }
  CdrBytes& Str(const std::string& s) {
    Put<uint32_t>(static_cast<uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
    return *this;
  }
  const std::vector<uint8_t>& bytes() const { return bytes_; }

 private:
  bool big_endian_;
  std::vector<uint8_t> bytes_;
};

CdrBytes ImuBytes(bool big_endian) {
  CdrBytes b(big_endian);
  b.Put<int32_t>(1700000000).Put<uint32_t>(5).Str("imu");  // 4+4+4+4 = 16 bytes: aligned
  for (int i = 0; i < 37; ++i) b.Put<double>(0.5 + i);
  return b;
}

class CdrImu : public ::testing::TestWithParam<bool> {};

TEST_P(CdrImu, DecodesEveryFieldInBothByteOrders) {
  const std::vector<uint8_t> bytes = ImuBytes(GetParam()).bytes();
  bag::ImuMessage imu;
  const Status status = DecodeImu(bytes.data(), bytes.size(), &imu);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(bag::RosTimeToNs(imu.header.stamp), 1700000000000000005LL);
  EXPECT_EQ(imu.header.frame_id, "imu");
  EXPECT_EQ(imu.orientation[0], 0.5);
  EXPECT_EQ(imu.orientation[3], 3.5);
  EXPECT_EQ(imu.orientation_covariance[8], 12.5);
  EXPECT_EQ(imu.angular_velocity[2], 15.5);
  EXPECT_EQ(imu.linear_acceleration[0], 25.5);
  EXPECT_EQ(imu.linear_acceleration_covariance[8], 36.5);
}

TEST_P(CdrImu, TruncatedMessageNamesTheField) {
  std::vector<uint8_t> bytes = ImuBytes(GetParam()).bytes();
  bytes.resize(bytes.size() - 8);
  bag::ImuMessage imu;
  const Status status = DecodeImu(bytes.data(), bytes.size(), &imu);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("linear_acceleration_covariance"), std::string::npos)
      << status.message();
}

INSTANTIATE_TEST_SUITE_P(ByteOrder, CdrImu, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "BigEndian" : "LittleEndian"; });

TEST(CdrReader, AlignsRelativeToThePayloadNotTheBuffer) {
  // u8, then a double at payload offset 8 (buffer offset 12: 4-aligned only).
  CdrBytes b(false);
  b.Put<uint8_t>(7).Put<double>(2.25);
  ASSERT_EQ(b.bytes().size(), 4u + 16u);
  CdrReader r;
  ASSERT_TRUE(r.Open(b.bytes().data(), b.bytes().size()).ok());
  uint8_t u = 0;
  double d = 0;
  ASSERT_TRUE(r.U8("u", &u).ok());
  ASSERT_TRUE(r.F64s("d", &d, 1).ok());
  EXPECT_EQ(u, 7);
  EXPECT_EQ(d, 2.25);
  EXPECT_TRUE(r.ExpectEnd("test").ok());
}

TEST(CdrReader, RejectsOtherEncapsulations) {
  const uint8_t xcdr2[] = {0, 0x11, 0, 0, 1, 0, 0, 0};
  CdrReader r;
  const Status status = r.Open(xcdr2, sizeof(xcdr2));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("not plain CDR"), std::string::npos) << status.message();
  EXPECT_FALSE(r.Open(xcdr2, 3).ok());
}

TEST(CdrReader, StringWithoutNulIsAnError) {
  std::vector<uint8_t> b = CdrBytes(false).Str("abc").bytes();
  b.back() = 'd';
  CdrReader r;
  ASSERT_TRUE(r.Open(b.data(), b.size()).ok());
  std::string s;
  const Status status = r.String("name", &s);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("name"), std::string::npos);
}

TEST(CdrReader, MoreThanPaddingAfterTheLastFieldIsAnError) {
  std::vector<uint8_t> bytes = ImuBytes(false).bytes();
  bytes.insert(bytes.end(), 3, 0);  // padding to 4: accepted
  bag::ImuMessage imu;
  EXPECT_TRUE(DecodeImu(bytes.data(), bytes.size(), &imu).ok());
  bytes.insert(bytes.end(), 5, 0);
  const Status status = DecodeImu(bytes.data(), bytes.size(), &imu);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("after the end"), std::string::npos) << status.message();
}

TEST(CdrPointCloud2, DecodesFieldsAndDataView) {
  CdrBytes b(true);
  b.Put<int32_t>(10).Put<uint32_t>(20).Str("lidar");
  b.Put<uint32_t>(1).Put<uint32_t>(2);  // height, width
  b.Put<uint32_t>(2).Str("x").Put<uint32_t>(0).Put<uint8_t>(7).Put<uint32_t>(1);
  b.Str("ring").Put<uint32_t>(4).Put<uint8_t>(4).Put<uint32_t>(1);
  b.Put<uint8_t>(1).Put<uint32_t>(6).Put<uint32_t>(12);  // is_bigendian, point_step, row_step
  b.Put<uint32_t>(12);
  for (uint8_t i = 0; i < 12; ++i) b.Put<uint8_t>(i);
  b.Put<uint8_t>(1);  // is_dense
  bag::PointCloud2View cloud;
  const Status status = DecodePointCloud2(b.bytes().data(), b.bytes().size(), &cloud);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(bag::RosTimeToNs(cloud.header.stamp), 10000000020LL);
  EXPECT_EQ(cloud.header.frame_id, "lidar");
  EXPECT_EQ(cloud.width, 2u);
  ASSERT_EQ(cloud.fields.size(), 2u);
  EXPECT_EQ(cloud.fields[1].name, "ring");
  EXPECT_EQ(cloud.fields[1].offset, 4u);
  EXPECT_EQ(cloud.fields[1].datatype, bag::kUint16);
  EXPECT_TRUE(cloud.is_bigendian);
  EXPECT_EQ(cloud.row_step, 12u);
  ASSERT_EQ(cloud.data_size, 12u);
  EXPECT_EQ(cloud.data[11], 11);
  EXPECT_TRUE(cloud.is_dense);
}

TEST(CdrImuHeader, NegativeSecondsAreAnError) {
  CdrBytes b(false);
  b.Put<int32_t>(-1).Put<uint32_t>(0).Str("imu");
  for (int i = 0; i < 37; ++i) b.Put<double>(0);
  bag::ImuMessage imu;
  const Status status = DecodeImu(b.bytes().data(), b.bytes().size(), &imu);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("before 1970"), std::string::npos);
}

}  // namespace
}  // namespace tiltcal::ros2
