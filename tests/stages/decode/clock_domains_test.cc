#include "stages/decode/clock_domains.h"

#include <string>

#include <gtest/gtest.h>

namespace tiltcal::decode {
namespace {

constexpr int64_t kSecond = 1000000000LL;
constexpr int64_t kT0 = 1700000000LL * kSecond;

TEST(StampOverlapSeconds, OverlapOrGap) {
  const StampSpan imu{kT0, kT0 + 40 * kSecond, 0};
  EXPECT_DOUBLE_EQ(StampOverlapSeconds(imu, {kT0 + 10 * kSecond, kT0 + 50 * kSecond, 0}), 30.0);
  EXPECT_DOUBLE_EQ(StampOverlapSeconds(imu, {kT0 + 5 * kSecond, kT0 + 6 * kSecond, 0}), 1.0);
  EXPECT_DOUBLE_EQ(StampOverlapSeconds(imu, {kT0 + 45 * kSecond, kT0 + 50 * kSecond, 0}), -5.0);
}

TEST(CheckClockDomains, PartialOverlapIsFine) {
  const StampSpan imu{kT0, kT0 + 40 * kSecond, 0};
  EXPECT_TRUE(CheckClockDomains("a.bag", imu, {kT0 + 39 * kSecond, kT0 + 80 * kSecond, 0}, 0.0)
                  .ok());
}

// The record times say where each sensor's stamps are against the
// recorder's clock: the LiDAR stamps 600 s ahead of it, the IMU 2 ms behind.
TEST(SuggestedLidarStampShiftSeconds, FromTheRecordDelays) {
  const StampSpan imu{kT0, kT0 + 40 * kSecond, 2000000};
  const StampSpan lidar{kT0 + 600 * kSecond, kT0 + 640 * kSecond, -600 * kSecond + 30000000};
  EXPECT_NEAR(SuggestedLidarStampShiftSeconds(imu, lidar, 0.0), -599.972, 1e-9);
  // Stamps already shifted by -100 s: the suggestion is the total.
  const StampSpan shifted{kT0 + 500 * kSecond, kT0 + 540 * kSecond, -500 * kSecond + 30000000};
  EXPECT_NEAR(SuggestedLidarStampShiftSeconds(imu, shifted, -100.0), -599.972, 1e-9);
}

// A bag whose record times copy the header stamps (a converted dataset) says
// nothing about the clocks: the suggestion aligns the first stamps instead.
TEST(CheckClockDomains, RecordTimesThatCopyTheStampsSuggestAligningTheStarts) {
  const StampSpan imu{kT0, kT0 + 40 * kSecond, 0};
  const StampSpan lidar{kT0 - 3600 * kSecond, kT0 - 3560 * kSecond, 0};
  const Status status = CheckClockDomains("a.bag", imu, lidar, 0.5);
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.message(),
            "a.bag: the LiDAR and IMU stamps do not overlap (two clocks?): IMU stamps "
            "1700000000.000 .. 1700000040.000 s (2023-11-14 22:13:20 UTC .. 2023-11-14 22:14:00 "
            "UTC), LiDAR stamps 1699996400.000 .. 1699996440.000 s (2023-11-14 21:13:20 UTC .. "
            "2023-11-14 21:14:00 UTC) (after lidar_stamp_shift_s 0.500), the LiDAR 3560.000 s "
            "before the IMU; set lidar_stamp_shift_s in the decode params (added to every LiDAR "
            "stamp, s) to decode anyway: lidar_stamp_shift_s: 3600.500 would align the first "
            "stamps");
}

}  // namespace
}  // namespace tiltcal::decode
