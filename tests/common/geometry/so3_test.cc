#include "common/geometry/so3.h"

#include <cmath>
#include <random>
#include <vector>

#include <ceres/jet.h>
#include <gtest/gtest.h>
#include "tests/testing/random_vector.h"

namespace tiltcal::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Rotation vectors of many magnitudes: exactly 0, tiny, around the series
// switch-overs, large, and close to pi.
std::vector<Eigen::Vector3d> TestVectors() {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<Eigen::Vector3d> out = {Eigen::Vector3d::Zero()};
  for (double norm : {1e-14, 1e-10, 1e-8, 1e-5, 9.9e-5, 1.01e-4, 9.9e-3, 1.01e-2, 0.1, 1.0, 2.0,
                      3.0, kPi - 1e-3, kPi - 1e-6, kPi - 1e-9}) {
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d v = tiltcal::testing::RandomVector3(n, rng);
      out.push_back(norm * v.normalized());
    }
  }
  return out;
}

TEST(So3Test, HatIsCrossProduct) {
  const Eigen::Vector3d a(0.3, -1.2, 2.0), b(-0.7, 0.4, 1.1);
  EXPECT_LT((Hat(a) * b - a.cross(b)).norm(), 1e-15);
  EXPECT_LT((Hat(a) + Hat(a).transpose()).norm(), 1e-15);
}

TEST(So3Test, ExpMatchesAngleAxis) {
  for (const Eigen::Vector3d& phi : TestVectors()) {
    const double theta = phi.norm();
    const Eigen::Matrix3d expected =
        theta > 0 ? Eigen::AngleAxisd(theta, phi / theta).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
    EXPECT_LT((ExpMatrix(phi) - expected).norm(), 1e-14) << phi.transpose();
    EXPECT_LT((ExpQuaternion(phi).toRotationMatrix() - expected).norm(), 1e-14) << phi.transpose();
    EXPECT_NEAR(ExpQuaternion(phi).norm(), 1.0, 1e-15);
  }
}

TEST(So3Test, LogInvertsExp) {
  for (const Eigen::Vector3d& phi : TestVectors()) {
    // |phi| < pi: the logarithm returns phi itself.
    EXPECT_LT((LogQuaternion(ExpQuaternion(phi)) - phi).norm(), 1e-14 * (1.0 + phi.norm()))
        << phi.transpose();
    EXPECT_LT((LogMatrix(ExpMatrix(phi)) - phi).norm(), 1e-9 * (1.0 + phi.norm()))
        << phi.transpose();
    // q and -q are the same rotation.
    const Eigen::Quaterniond q = ExpQuaternion(phi);
    const Eigen::Quaterniond minus_q(-q.w(), -q.x(), -q.y(), -q.z());
    EXPECT_LT((LogQuaternion(minus_q) - phi).norm(), 1e-14 * (1.0 + phi.norm()));
    // Scale invariance.
    EXPECT_LT((LogQuaternion(Eigen::Quaterniond(q.coeffs() * 3.0)) - phi).norm(), 1e-14 * (1.0 + phi.norm()));
  }
}

TEST(So3Test, ExpOfLogIsIdentityIncludingPi) {
  std::vector<Eigen::Matrix3d> rotations;
  for (const Eigen::Vector3d& phi : TestVectors()) rotations.push_back(ExpMatrix(phi));
  // Exactly pi about several axes (Log is then ambiguous in sign; Exp(Log) is not).
  for (const Eigen::Vector3d& axis :
       {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0.6, 0.0, 0.8),
        Eigen::Vector3d(1, 1, 1).normalized()}) {
    rotations.push_back(Eigen::AngleAxisd(kPi, axis).toRotationMatrix());
  }
  for (const Eigen::Matrix3d& r : rotations) {
    const Eigen::Vector3d phi = LogMatrix(r);
    EXPECT_LE(phi.norm(), kPi + 1e-12);
    EXPECT_LT((ExpMatrix(phi) - r).norm(), 1e-13) << r;
    const Eigen::Quaterniond q(r);
    EXPECT_LT((ExpQuaternion(LogQuaternion(q)).toRotationMatrix() - r).norm(), 1e-13);
  }
}

// Central differences of phi -> Log(Exp(phi)^T Exp(phi + h e_k)): column k of Jr.
Eigen::Matrix3d NumericRightJacobian(const Eigen::Vector3d& phi) {
  const double h = 1e-6;
  Eigen::Matrix3d j;
  const Eigen::Matrix3d r_t = ExpMatrix(phi).transpose();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(k);
    j.col(k) = (LogMatrix(r_t * ExpMatrix(phi + e)) - LogMatrix(r_t * ExpMatrix(phi - e))) / (2 * h);
  }
  return j;
}

Eigen::Matrix3d NumericLeftJacobian(const Eigen::Vector3d& phi) {
  const double h = 1e-6;
  Eigen::Matrix3d j;
  const Eigen::Matrix3d r_t = ExpMatrix(phi).transpose();
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(k);
    j.col(k) = (LogMatrix(ExpMatrix(phi + e) * r_t) - LogMatrix(ExpMatrix(phi - e) * r_t)) / (2 * h);
  }
  return j;
}

TEST(So3Test, RightAndLeftJacobiansMatchFiniteDifferences) {
  for (const Eigen::Vector3d& phi : TestVectors()) {
    if (phi.norm() > 3.0) continue;  // FD through Log near pi is ill-conditioned.
    EXPECT_LT((RightJacobian(phi) - NumericRightJacobian(phi)).norm(), 1e-8) << phi.transpose();
    EXPECT_LT((LeftJacobian(phi) - NumericLeftJacobian(phi)).norm(), 1e-8) << phi.transpose();
    EXPECT_LT((LeftJacobian(phi) - RightJacobian(phi).transpose()).norm(), 1e-15);
    Eigen::Matrix3d e, jr;
    ExpMatrixAndRightJacobian(phi, &e, &jr);
    EXPECT_LT((e - ExpMatrix(phi)).norm(), 1e-15);
    EXPECT_LT((jr - RightJacobian(phi)).norm(), 1e-15);
  }
}

TEST(So3Test, InverseJacobiansAreInverses) {
  for (const Eigen::Vector3d& phi : TestVectors()) {
    if (phi.norm() > kPi - 1e-4) continue;  // Jr^{-1} grows like 1/(2 pi - t); fine, but check separately.
    EXPECT_LT((RightJacobianInverse(phi) * RightJacobian(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-12)
        << phi.transpose();
    EXPECT_LT((LeftJacobianInverse(phi) * LeftJacobian(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  }
  // Near pi the closed form uses cot(t/2) and stays finite.
  const Eigen::Vector3d phi = (kPi - 1e-9) * Eigen::Vector3d(0.0, 0.6, 0.8);
  EXPECT_LT((RightJacobianInverse(phi) * RightJacobian(phi) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
}

TEST(So3Test, ExpAndLogHaveFiniteJetDerivativesAtZero) {
  using J = ceres::Jet<double, 3>;
  const Eigen::Matrix<J, 3, 1> phi(J(0.0, 0), J(0.0, 1), J(0.0, 2));
  const Eigen::Quaternion<J> q = ExpQuaternion(phi);
  // d vec(Exp(phi)) / d phi = I/2, d w / d phi = 0 at 0.
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(q.vec()[r].v[c], r == c ? 0.5 : 0.0);
    EXPECT_DOUBLE_EQ(q.w().v[r], 0.0);
  }
  // Log(Exp(phi)) = phi: Jacobian I.
  const Eigen::Matrix<J, 3, 1> back = LogQuaternion(q);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back[r].v[c], r == c ? 1.0 : 0.0, 1e-15);
  }
}

TEST(So3Test, BoxOperationsAndQuaternionJacobians) {
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Quaterniond q = ExpQuaternion(tiltcal::testing::RandomVector3(n, rng));
    const Eigen::Vector3d delta = 0.5 * tiltcal::testing::RandomVector3(n, rng);
    // Right perturbation: q Exp(delta) as matrices is R Exp(delta).
    EXPECT_LT((BoxPlus(q, delta).toRotationMatrix() - q.toRotationMatrix() * ExpMatrix(delta)).norm(), 1e-14);
    EXPECT_LT((BoxMinus(BoxPlus(q, delta), q) - delta).norm(), 1e-13);
    const Eigen::Matrix<double, 4, 3> plus = QuaternionPlusJacobian(q);
    const Eigen::Matrix<double, 3, 4> minus = QuaternionMinusJacobian(q);
    EXPECT_LT((minus * plus - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_LT((minus - 4.0 * plus.transpose()).norm(), 1e-14);
    // PlusJacobian vs central differences of BoxPlus (unnormalised product).
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = h * Eigen::Vector3d::Unit(k);
      const Eigen::Vector4d fd = ((q * ExpQuaternion(e)).coeffs() - (q * ExpQuaternion(Eigen::Vector3d(-e))).coeffs()) / (2 * h);
      EXPECT_LT((fd - plus.col(k)).norm(), 1e-9);
    }
  }
}

}  // namespace
}  // namespace tiltcal::geometry
