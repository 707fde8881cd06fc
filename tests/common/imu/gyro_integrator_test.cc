#include "common/imu/gyro_integrator.h"

#include <gtest/gtest.h>

#include "common/geometry/so3.h"
#include "tests/common/imu/synthetic_imu.h"

namespace tiltcal::imu {
namespace {

TEST(GyroIntegrator, ConstantRateGivesTheExactRotation) {
  const Eigen::Vector3d w(0.3, -0.2, 0.9);
  const auto readings = testing::SyntheticImu(
      100, 2, [&](double) { return w; }, Eigen::Quaterniond::Identity(), {0, 0, -9.81},
      Eigen::Vector3d::Zero(), 0, 0, nullptr);
  const GyroIntegrator integrator(readings, Eigen::Vector3d::Zero());
  for (double t : {0.0, 0.37, 1.0, 1.555, 2.0}) {
    const Eigen::Quaterniond expected = geometry::ExpQuaternion(Eigen::Vector3d(w * t));
    EXPECT_LT(geometry::BoxMinus(integrator.Rotation(t), expected).norm(), 1e-10) << t;
  }
  EXPECT_LT(geometry::BoxMinus(integrator.RelativeRotation(0.5, 1.5),
                               geometry::ExpQuaternion(Eigen::Vector3d(w)))
                .norm(),
            1e-10);
}

TEST(GyroIntegrator, TracksAVaryingRateAndRemovesTheBias) {
  const Eigen::Vector3d bias(0.01, -0.02, 0.005);
  std::vector<Eigen::Quaterniond> truth;
  auto omega = [](double t) {
    return Eigen::Vector3d(0.5 * std::sin(2 * t), 0.3 * std::cos(3 * t), 0.8 * std::sin(t));
  };
  const auto readings = testing::SyntheticImu(200, 10, omega, Eigen::Quaterniond::Identity(),
                                              {0, 0, -9.81}, bias, 0, 0, &truth);
  const GyroIntegrator integrator(readings, bias);
  double worst = 0;
  for (size_t k = 0; k < readings.size(); k += 50) {
    worst = std::max(worst,
                     geometry::BoxMinus(integrator.Rotation(readings[k].time_s), truth[k]).norm());
  }
  EXPECT_LT(worst, 1e-4);  // rad after 10 s at 200 Hz (second-order rule)
  const GyroIntegrator biased(readings, Eigen::Vector3d::Zero());
  EXPECT_GT(geometry::BoxMinus(biased.Rotation(10.0), truth.back()).norm(), 0.05);
}

}  // namespace
}  // namespace tiltcal::imu
