#include "common/spline/linear_interpolation.h"

#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::spline {
namespace {

TEST(InterpolateLinearly, BetweenSamplesAndClampedOutside) {
  const std::vector<double> times = {1.0, 2.0, 4.0};
  const std::vector<Eigen::Vector3d> values = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 4, 6),
                                               Eigen::Vector3d(-2, 4, 10)};
  EXPECT_TRUE(InterpolateLinearly(times, values, 1.5).isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_TRUE(InterpolateLinearly(times, values, 3.5).isApprox(Eigen::Vector3d(-1, 4, 9)));
  EXPECT_EQ(InterpolateLinearly(times, values, 2.0), values[1]);
  EXPECT_EQ(InterpolateLinearly(times, values, 0.0), values.front());
  EXPECT_EQ(InterpolateLinearly(times, values, 9.0), values.back());
  EXPECT_EQ(InterpolateLinearly({5.0}, {Eigen::Vector3d(7, 8, 9)}, 6.0), Eigen::Vector3d(7, 8, 9));
}

}  // namespace
}  // namespace tiltcal::spline
