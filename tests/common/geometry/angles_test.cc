#include "common/geometry/angles.h"

#include <cmath>

#include <gtest/gtest.h>

namespace tiltcal::geometry {
namespace {

TEST(AngleBetweenDeg, RightAnglesAndOpposites) {
  EXPECT_DOUBLE_EQ(AngleBetweenDeg(Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY()), 90.0);
  EXPECT_DOUBLE_EQ(AngleBetweenDeg(Eigen::Vector3d::UnitZ(), -Eigen::Vector3d::UnitZ()), 180.0);
  EXPECT_EQ(AngleBetweenDeg(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(2, 4, 6)), 0.0);
}

TEST(AngleBetweenDeg, IndependentOfLengthAndAccurateNearZero) {
  // 1e-9 rad apart, where acos of the normalised dot product returns 0.
  const double angle_rad = 1e-9;
  const Eigen::Vector3d a(3.0, 0.0, 0.0);
  const Eigen::Vector3d b = 0.2 * Eigen::Vector3d(std::cos(angle_rad), std::sin(angle_rad), 0.0);
  EXPECT_NEAR(AngleBetweenDeg(a, b), RadToDeg(angle_rad), 1e-12 * RadToDeg(angle_rad));
  EXPECT_NEAR(AngleBetweenDeg(a, Eigen::Vector3d(1.0, 1.0, 0.0)), 45.0, 1e-12);
}

}  // namespace
}  // namespace tiltcal::geometry
