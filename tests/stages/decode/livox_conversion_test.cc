// ConvertLivoxCustomMsgToScan on hand-made messages: point times relative to
// the stamp on either side of it, the drop order and counts, and the errors
// (timebase off its stamp, a point time outside int32 ns, frame_id not UTF-8).
#include "stages/decode/livox_conversion.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace tiltcal {
namespace {

bag::LivoxPoint Point(uint32_t offset_time, float x, float y, float z, uint8_t tag = 0,
                      uint8_t line = 0) {
  bag::LivoxPoint p;
  p.offset_time = offset_time;
  p.x = x;
  p.y = y;
  p.z = z;
  p.reflectivity = 42;
  p.tag = tag;
  p.line = line;
  return p;
}

bag::LivoxCustomMessage Message(int64_t stamp_ns, int64_t timebase_ns) {
  bag::LivoxCustomMessage m;
  m.header.stamp.sec = static_cast<uint32_t>(stamp_ns / 1000000000);
  m.header.stamp.nsec = static_cast<uint32_t>(stamp_ns % 1000000000);
  m.header.frame_id = "livox_frame";
  m.timebase = static_cast<uint64_t>(timebase_ns);
  return m;
}

proto::LivoxParams Params(uint32_t mask, double max_difference_s) {
  proto::LivoxParams p;
  p.set_noise_tag_mask(mask);
  p.set_max_timebase_stamp_difference_s(max_difference_s);
  return p;
}

constexpr int64_t kStamp = 1700000000500000000;

TEST(LivoxConversion, PointTimesAreTimebasePlusOffsetRelativeToTheStamp) {
  // timebase 2 ms before the stamp: the first point has a negative offset.
  bag::LivoxCustomMessage m = Message(kStamp, kStamp - 2000000);
  m.points = {Point(0, 1, 2, 3, 0x10, 5), Point(5000000, -4, 5, -6, 0x20, 1)};
  proto::Scan scan;
  ASSERT_TRUE(ConvertLivoxCustomMsgToScan(m, Params(0x0F, 0.1), 0.5, &scan).ok());
  EXPECT_EQ(scan.stamp_ns(), kStamp);
  EXPECT_EQ(scan.frame_id(), "livox_frame");
  EXPECT_EQ(scan.time_source(), proto::POINT_TIME_LIVOX_CUSTOM_MSG);
  ASSERT_EQ(scan.x_size(), 2);
  EXPECT_EQ(scan.time_offset_ns(0), -2000000);
  EXPECT_EQ(scan.time_offset_ns(1), 3000000);
  EXPECT_EQ(scan.x(1), -4.0f);
  EXPECT_EQ(scan.y(1), 5.0f);
  EXPECT_EQ(scan.z(1), -6.0f);
  EXPECT_EQ(scan.intensity(0), 42.0f);
  EXPECT_EQ(scan.ring(0), 5u);  // return-number bits are not noise
  EXPECT_EQ(scan.ring(1), 1u);
}

TEST(LivoxConversion, DropOrderInvalidThenRangeThenTag) {
  bag::LivoxCustomMessage m = Message(kStamp, kStamp);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  m.points = {Point(0, nan, 1, 1, 0x01),  // invalid (before its tag)
              Point(1, 0, 0, 0, 0x01),    // no return (before its tag)
              Point(2, 0.3f, 0, 0),       // closer than 0.5 m
              Point(3, 10, 0, 0, 0x01),   // spatial noise
              Point(4, 10, 0, 0, 0x08),   // intensity noise
              Point(5, 10, 0, 0, 0x30),   // return 3: kept
              Point(6, std::numeric_limits<float>::infinity(), 0, 0)};
  proto::Scan scan;
  ASSERT_TRUE(ConvertLivoxCustomMsgToScan(m, Params(0x0F, 0.1), 0.5, &scan).ok());
  EXPECT_EQ(scan.x_size(), 1);
  EXPECT_EQ(scan.time_offset_ns(0), 5);
  EXPECT_EQ(scan.num_dropped_invalid(), 2u);
  EXPECT_EQ(scan.num_dropped_zero_range(), 2u);
  EXPECT_EQ(scan.num_dropped_noise_tag(), 2u);
  // Mask 0: nothing is noise.
  ASSERT_TRUE(ConvertLivoxCustomMsgToScan(m, Params(0, 0.1), 0.5, &scan).ok());
  EXPECT_EQ(scan.x_size(), 3);
  EXPECT_EQ(scan.num_dropped_noise_tag(), 0u);
}

TEST(LivoxConversion, ClockAndRangeErrors) {
  proto::Scan scan;
  // timebase 0.2 s after the stamp, more than the 0.1 s allowed.
  bag::LivoxCustomMessage m = Message(kStamp, kStamp + 200000000);
  m.points = {Point(0, 10, 0, 0)};
  Status status = ConvertLivoxCustomMsgToScan(m, Params(0x0F, 0.1), 0.5, &scan);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("0.200000 s from header.stamp"), std::string::npos)
      << status.message();
  // An offset_time of 3 s: the point time leaves the int32 ns column.
  m = Message(kStamp, kStamp);
  m.points = {Point(3000000000u, 10, 0, 0)};
  status = ConvertLivoxCustomMsgToScan(m, Params(0x0F, 0.1), 0.5, &scan);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("outside the int32 ns range"), std::string::npos)
      << status.message();
  // A timebase past int64 (a garbage field).
  m = Message(kStamp, kStamp);
  m.timebase = std::numeric_limits<uint64_t>::max();
  EXPECT_FALSE(ConvertLivoxCustomMsgToScan(m, Params(0x0F, 0.1), 0.5, &scan).ok());
  // frame_id that is not UTF-8 could not be written into the Scan.
  m = Message(kStamp, kStamp);
  m.header.frame_id = "\xff\xfe";
  status = ConvertLivoxCustomMsgToScan(m, Params(0x0F, 0.1), 0.5, &scan);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("UTF-8"), std::string::npos);
}

}  // namespace
}  // namespace tiltcal
