#include "common/imu/imu_initialisation.h"

#include <gtest/gtest.h>

#include "tests/common/imu/synthetic_imu.h"
#include "tests/common/imu/imu_test_options.h"

namespace tiltcal::imu {
namespace {

using testing::ImuInitialisationTestOptions;

TEST(ImuInitialisation, StaticStartGivesBiasAndGravityInTheFirstImuFrame) {
  // IMU mounted upside down and tilted: gravity in a = C_ab0^T g_w.
  const Eigen::Quaterniond c_w_b0(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d bias(0.003, -0.002, 0.001);
  const auto readings = testing::SyntheticImu(
      200, 6, [](double t) { return t < 2 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(0, 0.2, 0.6); },
      c_w_b0, {0, 0, -9.81}, bias, 0.001, 0.02, nullptr);
  ImuInitialisation init;
  ASSERT_TRUE(InitialiseImu(readings, ImuInitialisationTestOptions(), &init).ok());
  ASSERT_TRUE(init.from_static_start);
  EXPECT_LT((init.gyro_bias_radps - bias).norm(), 3e-4);
  const Eigen::Vector3d expected = c_w_b0.conjugate() * Eigen::Vector3d(0, 0, -9.81);
  EXPECT_LT((init.gravity_in_world_mps2 - expected).norm(), 0.01);
  EXPECT_NEAR(init.gravity_in_world_mps2.norm(), 9.81, 1e-12);
}

TEST(ImuInitialisation, WithoutStaticStartUsesTheFirstSeconds) {
  const auto readings = testing::SyntheticImu(
      200, 5, [](double t) { return Eigen::Vector3d(0, 0, 0.5); }, Eigen::Quaterniond::Identity(),
      {0, 0, -9.81}, Eigen::Vector3d::Zero(), 0.0, 0.0, nullptr);
  ImuInitialisation init;
  ASSERT_TRUE(InitialiseImu(readings, ImuInitialisationTestOptions(), &init).ok());
  EXPECT_FALSE(init.from_static_start);
  EXPECT_LT((init.gravity_in_world_mps2 - Eigen::Vector3d(0, 0, -9.81)).norm(), 1e-6);
  EXPECT_GT(init.num_samples_averaged, 300);
}

}  // namespace
}  // namespace tiltcal::imu
