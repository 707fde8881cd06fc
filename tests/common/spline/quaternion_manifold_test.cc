#include "common/spline/quaternion_manifold.h"

#include <random>

#include <ceres/manifold_test_utils.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "common/geometry/so3.h"
#include "tests/testing/random_vector.h"

namespace tiltcal::spline {
namespace {

using ceres::HasCorrectMinusJacobianAt;
using ceres::HasCorrectPlusJacobianAt;
using ceres::HasCorrectRightMultiplyByPlusJacobianAt;
using ceres::Matrix;
using ceres::MinusPlusIsIdentityAt;
using ceres::MinusPlusJacobianIsIdentityAt;
using ceres::PlusMinusIsIdentityAt;
using ceres::Vector;
using ceres::XMinusXIsZeroAt;
using ceres::XPlusZeroIsXAt;

Vector RandomUnitQuaternion(std::mt19937* rng, double angle_scale) {
  std::normal_distribution<double> n(0.0, angle_scale);
  const Eigen::Quaterniond q = geometry::ExpQuaternion(tiltcal::testing::RandomVector3(n, *rng));
  return Eigen::Vector4d(q.coeffs());  // (x, y, z, w)
}

TEST(RightQuaternionManifoldTest, InvariantsHold) {
  RightQuaternionManifold manifold;
  std::mt19937 rng(23);
  std::normal_distribution<double> n(0.0, 0.5);
  for (int trial = 0; trial < 20; ++trial) {
    const Vector x = RandomUnitQuaternion(&rng, 1.0);
    const Vector delta = tiltcal::testing::RandomVector3(n, rng);
    // y near x so that x^{-1} y has w > 0 and Plus(x, Minus(y, x)) == y exactly
    // (not -y).
    const Eigen::Quaterniond qx(Eigen::Vector4d(x).data());
    const Eigen::Quaterniond qy = qx * geometry::ExpQuaternion(tiltcal::testing::RandomVector3(n, rng));
    const Vector y = Eigen::Vector4d(qy.coeffs());
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-9);
  }
}

TEST(RightQuaternionManifoldTest, IsARightPerturbationInXyzwOrder) {
  RightQuaternionManifold manifold;
  const Eigen::Quaterniond q = geometry::ExpQuaternion(Eigen::Vector3d(0.3, -0.2, 1.1));
  const Eigen::Vector3d delta(0.05, 0.1, -0.07);
  Eigen::Vector4d out;
  ASSERT_TRUE(manifold.Plus(q.coeffs().data(), delta.data(), out.data()));
  const Eigen::Quaterniond result(out.data());  // Eigen's Map order: x, y, z, w
  EXPECT_LT((result.toRotationMatrix() - q.toRotationMatrix() * geometry::ExpMatrix(delta)).norm(), 1e-14);
  // Ceres' own EigenQuaternionManifold perturbs on the left: different result.
  EXPECT_GT((result.toRotationMatrix() - geometry::ExpMatrix(delta) * q.toRotationMatrix()).norm(), 1e-3);
}

TEST(RightQuaternionManifoldTest, TangentToAmbientRecoversTangentJacobian) {
  RightQuaternionManifold manifold;
  std::mt19937 rng(29);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 10; ++trial) {
    const Vector x = RandomUnitQuaternion(&rng, 1.0);
    Eigen::Matrix<double, 3, 3> jt;
    for (int i = 0; i < 9; ++i) jt.data()[i] = n(rng);
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> ambient;
    TangentToAmbientJacobian<3>(jt, x.data(), ambient.data());
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
    ASSERT_TRUE(manifold.PlusJacobian(x.data(), plus.data()));
    EXPECT_LT((ambient * plus - jt).norm(), 1e-14);
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> minus;
    ASSERT_TRUE(manifold.MinusJacobian(x.data(), minus.data()));
    EXPECT_LT((ambient - jt * minus).norm(), 1e-14);
  }
}

}  // namespace
}  // namespace tiltcal::spline
