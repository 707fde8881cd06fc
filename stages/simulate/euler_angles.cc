#include "stages/simulate/euler_angles.h"

#include <algorithm>
#include <cmath>

namespace tiltcal::simulate {

namespace {
constexpr double kDegToRad = M_PI / 180.0;
}  // namespace

Eigen::Matrix3d RotX(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, c, -s, 0, s, c;
  return r;
}

Eigen::Matrix3d RotY(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, 0, s, 0, 1, 0, -s, 0, c;
  return r;
}

Eigen::Matrix3d RotZ(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Eigen::Matrix3d r;
  r << c, -s, 0, s, c, 0, 0, 0, 1;
  return r;
}

Eigen::Matrix3d RotationFromEulerDeg(const Eigen::Vector3d& rpy_deg) {
  return RotZ(rpy_deg.z() * kDegToRad) * RotY(rpy_deg.y() * kDegToRad) *
         RotX(rpy_deg.x() * kDegToRad);
}

Eigen::Vector3d EulerDegFromRotation(const Eigen::Matrix3d& r) {
  // r = Rz(y) Ry(p) Rx(x): r(2,0) = -sin p, r(2,1) = cos p sin x, r(2,2) = cos p cos x,
  // r(1,0) = sin y cos p, r(0,0) = cos y cos p.
  const double pitch = std::asin(std::clamp(-r(2, 0), -1.0, 1.0));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw) / kDegToRad;
}

}  // namespace tiltcal::simulate
