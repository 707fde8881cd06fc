#include "common/spline/quaternion_manifold.h"

#include <Eigen/Geometry>

#include "common/geometry/so3.h"

namespace tiltcal::spline {

bool RightQuaternionManifold::Plus(const double* x, const double* delta,
                                   double* x_plus_delta) const {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  const Eigen::Map<const Eigen::Vector3d> d(delta);
  Eigen::Map<Eigen::Quaterniond> out(x_plus_delta);
  out = geometry::BoxPlus(Eigen::Quaterniond(q), d);
  return true;
}

bool RightQuaternionManifold::PlusJacobian(const double* x, double* jacobian) const {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  Eigen::Map<Eigen::Matrix<double, 4, 3, Eigen::RowMajor>> j(jacobian);
  j = geometry::QuaternionPlusJacobian(Eigen::Quaterniond(q));
  return true;
}

bool RightQuaternionManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const Eigen::Map<const Eigen::Quaterniond> qy(y);
  const Eigen::Map<const Eigen::Quaterniond> qx(x);
  Eigen::Map<Eigen::Vector3d> out(y_minus_x);
  out = geometry::LogQuaternion(Eigen::Quaterniond(qx.conjugate() * qy));
  return true;
}

bool RightQuaternionManifold::MinusJacobian(const double* x, double* jacobian) const {
  const Eigen::Map<const Eigen::Quaterniond> q(x);
  Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> j(jacobian);
  j = geometry::QuaternionMinusJacobian(Eigen::Quaterniond(q));
  return true;
}

}  // namespace tiltcal::spline
