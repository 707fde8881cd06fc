// PointField-driven conversion on clouds built byte by byte here, with the
// expected values written out independently of the decoder.
#include "stages/decode/point_cloud_conversion.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bag/ros1/message_encoding.h"

namespace tiltcal {
namespace {

using ros1::PointCloud2View;
using ros1::PointField;

// A cloud under construction: fields, points packed at point_step, rows
// padded to row_step.
class CloudBuilder {
 public:
  CloudBuilder(uint32_t point_step, uint32_t width, uint32_t height, uint32_t row_step = 0,
               bool big_endian = false)
      : big_endian_(big_endian) {
    view_.point_step = point_step;
    view_.width = width;
    view_.height = height;
    view_.row_step = row_step != 0 ? row_step : point_step * width;
    view_.is_bigendian = big_endian;
    view_.header.stamp = ros1::RosTime{1700000000, 500000000};
    view_.header.frame_id = "lidar";
    data_.assign(static_cast<size_t>(view_.row_step) * height, '\xAB');
  }
  void Field(const std::string& name, uint32_t offset, uint8_t type) {
    view_.fields.push_back(PointField{name, offset, type, 1});
  }
  template <typename T>
  void Set(uint32_t row, uint32_t col, uint32_t offset, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if (big_endian_) std::reverse(bytes, bytes + sizeof(T));
    std::memcpy(&data_[row * view_.row_step + col * view_.point_step + offset], bytes, sizeof(T));
  }
  const PointCloud2View& view() {
    view_.data = reinterpret_cast<const uint8_t*>(data_.data());
    view_.data_size = static_cast<uint32_t>(data_.size());
    return view_;
  }
  int64_t stamp_ns() const { return ros1::RosTimeToNs(view_.header.stamp); }

 private:
  bool big_endian_;
  PointCloud2View view_;
  std::string data_;
};

Status Convert(CloudBuilder& b, proto::Scan* scan, double min_range_m = 0.0) {
  PointConversionOptions options;
  options.min_range_m = min_range_m;
  return ConvertPointCloud2ToScan(b.view(), options, scan);
}

TEST(PointCloudConversion, VelodynePointStep22WithNegativeTimes) {
  CloudBuilder b(22, 3, 1);
  b.Field("x", 0, ros1::kFloat32);
  b.Field("y", 4, ros1::kFloat32);
  b.Field("z", 8, ros1::kFloat32);
  b.Field("intensity", 12, ros1::kFloat32);
  b.Field("ring", 16, ros1::kUint16);
  b.Field("time", 18, ros1::kFloat32);
  const float times[3] = {-0.099f, -0.05f, 0.0f};
  for (uint32_t c = 0; c < 3; ++c) {
    b.Set<float>(0, c, 0, 1.0f + c);
    b.Set<float>(0, c, 4, -2.0f);
    b.Set<float>(0, c, 8, 0.25f);
    b.Set<float>(0, c, 12, 10.0f * c);
    b.Set<uint16_t>(0, c, 16, static_cast<uint16_t>(31 - c));
    b.Set<float>(0, c, 18, times[c]);
  }
  proto::Scan scan;
  ASSERT_TRUE(Convert(b, &scan).ok());
  EXPECT_EQ(scan.time_source(), proto::POINT_TIME_VELODYNE_TIME);
  EXPECT_EQ(scan.stamp_ns(), b.stamp_ns());
  EXPECT_EQ(scan.frame_id(), "lidar");
  ASSERT_EQ(scan.x_size(), 3);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(scan.x(c), 1.0f + c);
    EXPECT_EQ(scan.y(c), -2.0f);
    EXPECT_EQ(scan.z(c), 0.25f);
    EXPECT_EQ(scan.intensity(c), 10.0f * c);
    EXPECT_EQ(scan.ring(c), 31u - c);
    EXPECT_EQ(scan.time_offset_ns(c), std::llround(static_cast<double>(times[c]) * 1e9));
  }
  EXPECT_LT(scan.time_offset_ns(0), -98000000);
}

// Found by fuzzing: a frame_id that is not UTF-8 made a Scan that protobuf
// writes (with a log line) but refuses to read back.
TEST(PointCloudConversion, FrameIdThatIsNotUtf8IsAnError) {
  for (const std::string& frame_id :
       {std::string("lidar\xff"), std::string("\xc0\xaf"), std::string("\xed\xa0\x80"),
        std::string("\xe2\x82")}) {
    CloudBuilder b(12, 1, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 8, ros1::kFloat32);
    PointCloud2View view = b.view();
    view.header.frame_id = frame_id;
    proto::Scan scan;
    const Status status = ConvertPointCloud2ToScan(view, {}, &scan);
    ASSERT_FALSE(status.ok());
    EXPECT_EQ(status.message(), "header.frame_id is not valid UTF-8");
  }
  CloudBuilder b(12, 1, 1);
  b.Field("x", 0, ros1::kFloat32);
  b.Field("y", 4, ros1::kFloat32);
  b.Field("z", 8, ros1::kFloat32);
  b.Set<float>(0, 0, 0, 5.0f);
  PointCloud2View view = b.view();
  view.header.frame_id = "capteur_\xc3\xa9t\xc3\xa9_\xe2\x82\xac_\xf0\x9f\x9a\x97";  // é, €, 🚗
  proto::Scan scan;
  ASSERT_TRUE(ConvertPointCloud2ToScan(view, {}, &scan).ok());
  EXPECT_EQ(scan.frame_id(), view.header.frame_id);
}

// Found by fuzzing (UBSan, float-cast-overflow): a float ring of -1 or NaN
// was cast to uint32. It is an error naming the point and the field.
TEST(PointCloudConversion, RingThatIsNoRingNumberIsAnError) {
  for (const float ring : {-1.0f, std::nanf(""), 5e9f}) {
    CloudBuilder b(16, 2, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 8, ros1::kFloat32);
    b.Field("ring", 12, ros1::kFloat32);
    for (uint32_t c = 0; c < 2; ++c) {
      b.Set<float>(0, c, 0, 5.0f);
      b.Set<float>(0, c, 4, 0.0f);
      b.Set<float>(0, c, 8, 0.0f);
      b.Set<float>(0, c, 12, c == 0 ? 3.0f : ring);
    }
    proto::Scan scan;
    const Status status = Convert(b, &scan);
    ASSERT_FALSE(status.ok()) << ring;
    EXPECT_EQ(status.message().rfind("point 1: its ring (field 'ring') is ", 0), 0u)
        << status.message();
  }
}

TEST(PointCloudConversion, Float64XyzAnyIntensityTypeLineAndOffsetTime) {
  CloudBuilder b(35, 2, 1);
  b.Field("x", 0, ros1::kFloat64);
  b.Field("y", 8, ros1::kFloat64);
  b.Field("z", 16, ros1::kFloat64);
  b.Field("reflectivity", 24, ros1::kUint8);
  b.Field("line", 25, ros1::kUint8);
  b.Field("offset_time", 26, ros1::kUint32);
  b.Field("tag", 30, ros1::kUint8);
  for (uint32_t c = 0; c < 2; ++c) {
    b.Set<double>(0, c, 0, 3.25 + c);
    b.Set<double>(0, c, 8, 1e-3);
    b.Set<double>(0, c, 16, -7.5);
    b.Set<uint8_t>(0, c, 24, static_cast<uint8_t>(200 + c));
    b.Set<uint8_t>(0, c, 25, static_cast<uint8_t>(5 + c));
    b.Set<uint32_t>(0, c, 26, 1000000u * (c + 1) + 7);
  }
  proto::Scan scan;
  ASSERT_TRUE(Convert(b, &scan).ok());
  EXPECT_EQ(scan.time_source(), proto::POINT_TIME_OFFSET_TIME_NS);
  ASSERT_EQ(scan.x_size(), 2);
  EXPECT_EQ(scan.x(1), 4.25f);
  EXPECT_EQ(scan.y(0), static_cast<float>(1e-3));
  EXPECT_EQ(scan.intensity(1), 201.0f);
  EXPECT_EQ(scan.ring(1), 6u);
  EXPECT_EQ(scan.time_offset_ns(1), 2000007);
}

TEST(PointCloudConversion, BigEndianCloud) {
  CloudBuilder b(20, 1, 1, 0, /*big_endian=*/true);
  b.Field("x", 0, ros1::kFloat32);
  b.Field("y", 4, ros1::kFloat32);
  b.Field("z", 8, ros1::kFloat32);
  b.Field("i", 12, ros1::kUint16);
  b.Field("t", 14, ros1::kUint32);
  b.Field("laser_id", 18, ros1::kUint16);
  b.Set<float>(0, 0, 0, 1.5f);
  b.Set<float>(0, 0, 4, -2.5f);
  b.Set<float>(0, 0, 8, 3.5f);
  b.Set<uint16_t>(0, 0, 12, 0x1234);
  b.Set<uint32_t>(0, 0, 14, 0x01020304);
  b.Set<uint16_t>(0, 0, 18, 300);
  proto::Scan scan;
  ASSERT_TRUE(Convert(b, &scan).ok());
  ASSERT_EQ(scan.x_size(), 1);
  EXPECT_EQ(scan.x(0), 1.5f);
  EXPECT_EQ(scan.y(0), -2.5f);
  EXPECT_EQ(scan.z(0), 3.5f);
  EXPECT_EQ(scan.intensity(0), static_cast<float>(0x1234));
  EXPECT_EQ(scan.time_offset_ns(0), 0x01020304);
  EXPECT_EQ(scan.ring(0), 300u);
  EXPECT_EQ(scan.time_source(), proto::POINT_TIME_OUSTER_T);
}

TEST(PointCloudConversion, OrganizedPaddedRowsDropInvalidAndShortRange) {
  // 2 rows x 3 columns, point_step 16, row_step 53 (5 padding bytes).
  CloudBuilder b(16, 3, 2, 53);
  b.Field("x", 0, ros1::kFloat32);
  b.Field("y", 4, ros1::kFloat32);
  b.Field("z", 8, ros1::kFloat32);
  b.Field("t", 12, ros1::kUint32);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const float xs[2][3] = {{1.0f, nan, 0.0f}, {0.3f, 2.0f, inf}};
  for (uint32_t r = 0; r < 2; ++r) {
    for (uint32_t c = 0; c < 3; ++c) {
      b.Set<float>(r, c, 0, xs[r][c]);
      b.Set<float>(r, c, 4, 0.0f);
      b.Set<float>(r, c, 8, 0.0f);
      b.Set<uint32_t>(r, c, 12, 100u * r + c);
    }
  }
  proto::Scan scan;
  ASSERT_TRUE(Convert(b, &scan, /*min_range_m=*/0.5).ok());
  // Kept: (0,0) x=1 and (1,1) x=2; NaN and Inf invalid; 0 and 0.3 m short.
  ASSERT_EQ(scan.x_size(), 2);
  EXPECT_EQ(scan.x(0), 1.0f);
  EXPECT_EQ(scan.time_offset_ns(0), 0);
  EXPECT_EQ(scan.x(1), 2.0f);
  EXPECT_EQ(scan.time_offset_ns(1), 101);
  EXPECT_EQ(scan.num_dropped_invalid(), 2u);
  EXPECT_EQ(scan.num_dropped_zero_range(), 2u);
  EXPECT_EQ(scan.ring_size(), 0);            // no ring field
  EXPECT_EQ(scan.intensity_size(), 2);       // zeros without an intensity field
  EXPECT_EQ(scan.intensity(0), 0.0f);
}

TEST(PointCloudConversion, AbsoluteTimestampSecondsAndNanoseconds) {
  {
    CloudBuilder b(26, 1, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 8, ros1::kFloat32);
    b.Field("timestamp", 18, ros1::kFloat64);
    b.Set<float>(0, 0, 0, 5.0f);
    // 1700000000.5 + 0.03125 s: exactly representable (ulp 2^-22 s).
    b.Set<double>(0, 0, 18, 1700000000.53125);
    proto::Scan scan;
    ASSERT_TRUE(Convert(b, &scan).ok());
    EXPECT_EQ(scan.time_source(), proto::POINT_TIME_ABSOLUTE_SECONDS);
    EXPECT_EQ(scan.time_offset_ns(0), 31250000);
  }
  {
    CloudBuilder b(26, 1, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 8, ros1::kFloat32);
    b.Field("timestamp", 18, ros1::kFloat64);
    b.Set<float>(0, 0, 0, 5.0f);
    // Livox driver 2: absolute ns as a double (exact: a multiple of 256 ns).
    b.Set<double>(0, 0, 18, static_cast<double>(b.stamp_ns() + 1024000));
    proto::Scan scan;
    ASSERT_TRUE(Convert(b, &scan).ok());
    EXPECT_EQ(scan.time_source(), proto::POINT_TIME_ABSOLUTE_NS_DOUBLE);
    EXPECT_EQ(scan.time_offset_ns(0), 1024000);
  }
}

TEST(PointCloudConversion, TimeSecNsecPairAndNoTime) {
  CloudBuilder b(20, 1, 1);
  b.Field("x", 0, ros1::kFloat32);
  b.Field("y", 4, ros1::kFloat32);
  b.Field("z", 8, ros1::kFloat32);
  b.Field("time_sec", 12, ros1::kUint32);
  b.Field("time_nsec", 16, ros1::kUint32);
  b.Set<float>(0, 0, 0, 5.0f);
  b.Set<uint32_t>(0, 0, 12, 1699999999u);
  b.Set<uint32_t>(0, 0, 16, 900000000u);
  proto::Scan scan;
  ASSERT_TRUE(Convert(b, &scan).ok());
  EXPECT_EQ(scan.time_source(), proto::POINT_TIME_SEC_NSEC);
  EXPECT_EQ(scan.time_offset_ns(0), -600000000);

  CloudBuilder n(12, 1, 1);
  n.Field("x", 0, ros1::kFloat32);
  n.Field("y", 4, ros1::kFloat32);
  n.Field("z", 8, ros1::kFloat32);
  n.Set<float>(0, 0, 0, 5.0f);
  ASSERT_TRUE(Convert(n, &scan).ok());
  EXPECT_EQ(scan.time_source(), proto::POINT_TIME_NONE);
  ASSERT_EQ(scan.time_offset_ns_size(), 1);
  EXPECT_EQ(scan.time_offset_ns(0), 0);
}

TEST(PointCloudConversion, LayoutErrors) {
  proto::Scan scan;
  {
    CloudBuilder b(12, 1, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    Status s = Convert(b, &scan);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("lacks an x, y or z"), std::string::npos) << s.message();
  }
  {
    CloudBuilder b(12, 1, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 10, ros1::kFloat32);  // 10 + 4 > 12
    Status s = Convert(b, &scan);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("outside the point_step"), std::string::npos) << s.message();
  }
  {
    CloudBuilder b(12, 4, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 8, ros1::kFloat32);
    PointCloud2View view = b.view();
    view.data_size -= 1;  // one byte short of 4 points
    Status s = ConvertPointCloud2ToScan(view, {}, &scan);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("need 48"), std::string::npos) << s.message();
  }
  {
    CloudBuilder b(16, 1, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 8, ros1::kFloat32);
    b.Field("t", 12, ros1::kFloat32);  // Ouster t must be integer ns
    Status s = Convert(b, &scan);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("'t' has datatype FLOAT32"), std::string::npos) << s.message();
  }
  {
    CloudBuilder b(20, 1, 1);
    b.Field("x", 0, ros1::kFloat32);
    b.Field("y", 4, ros1::kFloat32);
    b.Field("z", 8, ros1::kFloat32);
    b.Field("timestamp", 12, ros1::kFloat64);
    b.Set<float>(0, 0, 0, 5.0f);
    b.Set<double>(0, 0, 12, 1600000000.0);  // another clock than the stamp
    Status s = Convert(b, &scan);
    ASSERT_FALSE(s.ok());
    EXPECT_NE(s.message().find("offsets must stay within"), std::string::npos) << s.message();
  }
}

// Byte flips of a serialized cloud: whatever still decodes converts without
// a crash and never yields more points than the cloud has.
TEST(PointCloudConversion, CorruptedCloudsNeverCrash) {
  const std::vector<PointField> fields = {{"x", 0, ros1::kFloat32, 1},
                                          {"y", 4, ros1::kFloat32, 1},
                                          {"z", 8, ros1::kFloat32, 1},
                                          {"time", 12, ros1::kFloat32, 1}};
  std::string data;
  for (int i = 0; i < 24; ++i) ros1::AppendLe<float>(&data, 0.05f * i - 0.3f);
  std::string good;
  ASSERT_TRUE(ros1::SerializePointCloud2(7, 1700000000000000000, "l", 2, 3, fields, 16, data,
                                         /*is_dense=*/true, &good));
  {
    PointCloud2View cloud;
    ASSERT_TRUE(ros1::DecodePointCloud2(reinterpret_cast<const uint8_t*>(good.data()), good.size(),
                                        &cloud)
                    .ok());
    proto::Scan scan;
    Status status = ConvertPointCloud2ToScan(cloud, PointConversionOptions{}, &scan);
    ASSERT_TRUE(status.ok()) << status.message();
    EXPECT_EQ(scan.x_size() + scan.num_dropped_zero_range() + scan.num_dropped_invalid(), 6u);
  }
  for (size_t i = 0; i < good.size(); ++i) {
    for (uint8_t flip : {0x01, 0x80, 0xFF}) {
      std::string b = good;
      b[i] = static_cast<char>(b[i] ^ flip);
      PointCloud2View cloud;
      if (!ros1::DecodePointCloud2(reinterpret_cast<const uint8_t*>(b.data()), b.size(), &cloud)
               .ok()) {
        continue;
      }
      proto::Scan scan;
      (void)ConvertPointCloud2ToScan(cloud, PointConversionOptions{}, &scan);
      EXPECT_LE(scan.x_size(), 6);
    }
  }
}

}  // namespace
}  // namespace tiltcal
