// How much the motion turned (rig_rotation_check.h): the amounts, and the
// line that names the missing turning with the measured and needed values.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "stages/calibrate/init/rig_rotation_check.h"
#include "tests/stages/calibrate/calibrate_params_text.h"

namespace tiltcal::calibrate {
namespace {

// A pair rotating by `angle_rad` about `axis` in both frames, the LiDAR's
// axis given in its own frame.
RotationPair Pair(double angle_rad, const Eigen::Vector3d& axis_b, const Eigen::Vector3d& axis_l) {
  RotationPair p;
  p.imu_delta = Eigen::AngleAxisd(angle_rad, axis_b.normalized());
  p.lidar_delta = Eigen::AngleAxisd(angle_rad, axis_l.normalized());
  return p;
}

// Four turns of 0.3 rad one way and two of 0.2 rad the other, about -z_b
// (the IMU upside down), with a small roll wobble, 0.5 s each.
TEST(TurningAmount, MeasuresTheTurningAboutTheMainAxisBothWays) {
  std::vector<RotationPair> pairs;
  std::vector<std::pair<double, double>> times;
  const double angles[] = {0.3, 0.3, -0.2, 0.3, -0.2, 0.3};
  for (int k = 0; k < 6; ++k) {
    pairs.push_back(Pair(angles[k], Eigen::Vector3d(0.01 * (k % 2), 0, -1), Eigen::Vector3d::UnitZ()));
    times.emplace_back(2.0 + 0.5 * k, 2.5 + 0.5 * k);
  }
  const TurningAmount turning = MeasureTurning(pairs, times);
  EXPECT_EQ(turning.pairs, 6);
  EXPECT_DOUBLE_EQ(turning.span_s, 3.0);
  const double rms = std::sqrt((4 * 0.09 + 2 * 0.04) / 6.0);
  EXPECT_NEAR(turning.rms_about_axis_rad, rms, 1e-4);
  // The sign of the principal axis is the eigen solver's: one way is 1.2
  // rad, the other 0.4 rad.
  EXPECT_NEAR(std::max(turning.left_rad, turning.right_rad), 1.2, 1e-3);
  EXPECT_NEAR(std::min(turning.left_rad, turning.right_rad), 0.4, 1e-3);
  EXPECT_EQ(MissingTurning(turning, tiltcal::testing::DefaultCalibrateParamsWith().init()), "");
}

TEST(TurningAmount, TooLittleTurningIsNamedWithTheAmounts) {
  std::vector<RotationPair> pairs;
  std::vector<std::pair<double, double>> times;
  for (int k = 0; k < 4; ++k) {
    pairs.push_back(Pair(0.001 * (k + 1), Eigen::Vector3d(k, 1, 2), Eigen::Vector3d(1, k, 2)));
    times.emplace_back(0.5 * k, 0.5 * k + 0.5);
  }
  const TurningAmount turning = MeasureTurning(pairs, times);
  const std::string line =
      MissingTurning(turning, tiltcal::testing::DefaultCalibrateParamsWith().init());
  EXPECT_EQ(line.rfind("the motion cannot decide the extrinsic rotation: too little turning, ", 0),
            0u)
      << line;
  EXPECT_NE(line.find("(at least init.min_axis_rotation_rad = 0.02 rad), 4 pairs over 2.0 s"),
            std::string::npos)
      << line;
  EXPECT_NE(line.find("record 30 s or more of driving with turns both ways"), std::string::npos);
}

TEST(TurningAmount, NoRotationAtAll) {
  const std::vector<RotationPair> pairs(3);
  const TurningAmount turning = MeasureTurning(pairs, {});
  EXPECT_EQ(turning.rms_about_axis_rad, 0.0);
  EXPECT_EQ(turning.span_s, 0.0);
  EXPECT_NE(MissingTurning(turning, tiltcal::testing::DefaultCalibrateParamsWith().init()), "");
}

}  // namespace
}  // namespace tiltcal::calibrate
