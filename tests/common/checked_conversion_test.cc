#include "common/checked_conversion.h"

#include <cmath>
#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

namespace tiltcal {
namespace {

TEST(CheckedConversion, FloatToIntegerRefusesWhatDoesNotFit) {
  EXPECT_EQ(CheckedTruncate<int>(2.9), 2);
  EXPECT_EQ(CheckedTruncate<int>(-2.9), -2);
  EXPECT_EQ(CheckedTruncate<int>(2147483647.0), 2147483647);
  EXPECT_FALSE(CheckedTruncate<int>(2147483648.0));
  EXPECT_EQ(CheckedTruncate<int>(-2147483648.0), std::numeric_limits<int>::min());
  EXPECT_FALSE(CheckedTruncate<int>(-2147483649.0));
  EXPECT_FALSE(CheckedTruncate<int>(std::nan("")));
  EXPECT_FALSE(CheckedTruncate<int>(INFINITY));
  EXPECT_FALSE(CheckedTruncate<uint16_t>(-1.0));
  EXPECT_EQ(CheckedTruncate<uint16_t>(65535.0), 65535);
  EXPECT_FALSE(CheckedTruncate<uint16_t>(65536.0));
  EXPECT_FALSE(CheckedTruncate<int64_t>(9.3e18));
  EXPECT_EQ(CheckedCeil<int>(1e-300 / 1e-300), 1);
  EXPECT_FALSE(CheckedCeil<int>(1e300));
  EXPECT_EQ(CheckedRound<int>(2.5), 3);
  EXPECT_EQ(CheckedRound<int>(-2.5), -3);
}

TEST(CheckedConversion, StampArithmeticReportsOverflow) {
  EXPECT_EQ(SecondsToNs(1.5), 1500000000);
  EXPECT_FALSE(SecondsToNs(1e300));
  EXPECT_FALSE(SecondsToNs(std::nan("")));
  const int64_t max = std::numeric_limits<int64_t>::max();
  const int64_t min = std::numeric_limits<int64_t>::min();
  EXPECT_FALSE(CheckedAdd(max, 1));
  EXPECT_EQ(CheckedAdd(max, -1), max - 1);
  EXPECT_FALSE(CheckedSub(min, 1));
  EXPECT_FALSE(CheckedSub(0, min));
  EXPECT_EQ(DifferenceSeconds(3000000000, 1000000000), 2.0);
  // max − min overflows int64 but not the difference in seconds.
  EXPECT_NEAR(DifferenceSeconds(max, min), 18446744073.709551615, 1e-3);
  EXPECT_NEAR(DifferenceSeconds(min, max), -18446744073.709551615, 1e-3);
}

}  // namespace
}  // namespace tiltcal
