#include "common/geometry/so3.h"

#include <cmath>

namespace tiltcal::geometry {
namespace {

// Below this angle (rad) the trigonometric coefficients are replaced by their
// Taylor series: the closed forms lose ~eps/t^2 to cancellation there, the
// truncated series errs by < t^6/5040 ~ 2e-16.
constexpr double kSeriesAngle = 1e-2;
constexpr double kSeriesAngleSq = kSeriesAngle * kSeriesAngle;

// a = sin(t)/t, b = (1 - cos t)/t^2, c = (t - sin t)/t^3.
void RodriguesCoefficients(double theta_sq, double* a, double* b, double* c) {
  if (theta_sq < kSeriesAngleSq) {
    const double t2 = theta_sq;
    const double t4 = t2 * t2;
    *a = 1.0 - t2 / 6.0 + t4 / 120.0;
    *b = 0.5 - t2 / 24.0 + t4 / 720.0;
    *c = 1.0 / 6.0 - t2 / 120.0 + t4 / 5040.0;
  } else {
    const double t = std::sqrt(theta_sq);
    const double s = std::sin(t);
    const double co = std::cos(t);
    *a = s / t;
    *b = (1.0 - co) / theta_sq;
    *c = (t - s) / (theta_sq * t);
  }
}

}  // namespace

Eigen::Matrix3d ExpMatrix(const Eigen::Vector3d& phi) {
  double a, b, c;
  RodriguesCoefficients(phi.squaredNorm(), &a, &b, &c);
  const Eigen::Matrix3d h = Hat(phi);
  return Eigen::Matrix3d::Identity() + a * h + b * h * h;
}

Eigen::Vector3d LogMatrix(const Eigen::Matrix3d& rotation) {
  return LogQuaternion(Eigen::Quaterniond(rotation));
}

Eigen::Matrix3d RightJacobian(const Eigen::Vector3d& phi) {
  double a, b, c;
  RodriguesCoefficients(phi.squaredNorm(), &a, &b, &c);
  const Eigen::Matrix3d h = Hat(phi);
  return Eigen::Matrix3d::Identity() - b * h + c * h * h;
}

void ExpMatrixAndRightJacobian(const Eigen::Vector3d& phi, Eigen::Matrix3d* exp,
                               Eigen::Matrix3d* right_jacobian) {
  double a, b, c;
  RodriguesCoefficients(phi.squaredNorm(), &a, &b, &c);
  const Eigen::Matrix3d h = Hat(phi);
  const Eigen::Matrix3d h2 = h * h;
  *exp = Eigen::Matrix3d::Identity() + a * h + b * h2;
  *right_jacobian = Eigen::Matrix3d::Identity() - b * h + c * h2;
}

Eigen::Matrix3d RightJacobianInverse(const Eigen::Vector3d& phi) {
  const double t2 = phi.squaredNorm();
  double e;  // 1/t^2 - cot(t/2) / (2 t)
  if (t2 < kSeriesAngleSq) {
    e = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  } else {
    const double t = std::sqrt(t2);
    const double half = 0.5 * t;
    e = 1.0 / t2 - std::cos(half) / (2.0 * t * std::sin(half));
  }
  const Eigen::Matrix3d h = Hat(phi);
  return Eigen::Matrix3d::Identity() + 0.5 * h + e * h * h;
}

Eigen::Matrix<double, 4, 3> QuaternionPlusJacobian(const Eigen::Quaterniond& q) {
  Eigen::Matrix<double, 4, 3> j;
  j.topRows<3>() = 0.5 * (q.w() * Eigen::Matrix3d::Identity() + Hat(Eigen::Vector3d(q.vec())));
  j.bottomRows<1>() = -0.5 * q.vec().transpose();
  return j;
}

Eigen::Matrix<double, 3, 4> QuaternionMinusJacobian(const Eigen::Quaterniond& q) {
  Eigen::Matrix<double, 3, 4> j;
  j.leftCols<3>() = 2.0 * (q.w() * Eigen::Matrix3d::Identity() - Hat(Eigen::Vector3d(q.vec())));
  j.rightCols<1>() = -2.0 * q.vec();
  return j;
}

}  // namespace tiltcal::geometry
