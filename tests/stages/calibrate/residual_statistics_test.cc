#include "stages/calibrate/residual_statistics.h"

#include <gtest/gtest.h>

namespace tiltcal::calibrate {
namespace {

// Bins of 0.25 from -5: -5.0 is bin 0, -0.1 bin 19, 0.0 and 0.2 bin 20,
// 4.99 bin 39; -5.01 is below, 5.0 above.
TEST(ResidualHistogram, CountsSignedValuesPerBinAndOutsideTheRange) {
  const proto::ResidualStatistics s =
      SummariseResiduals("lidar", {-5.0, -0.1, 0.0, 0.2, 4.99, -5.01, 5.0, 7.0});
  EXPECT_EQ(s.histogram_min(), -5.0);
  EXPECT_EQ(s.histogram_bin_width(), 0.25);
  ASSERT_EQ(s.histogram_counts_size(), 40);
  EXPECT_EQ(s.histogram_counts(0), 1);
  EXPECT_EQ(s.histogram_counts(19), 1);
  EXPECT_EQ(s.histogram_counts(20), 2);
  EXPECT_EQ(s.histogram_counts(39), 1);
  int inside = 0;
  for (const int c : s.histogram_counts()) inside += c;
  EXPECT_EQ(inside, 5);
  EXPECT_EQ(s.histogram_below(), 1);
  EXPECT_EQ(s.histogram_above(), 2);
  EXPECT_EQ(s.count(), 8);
}

}  // namespace
}  // namespace tiltcal::calibrate
