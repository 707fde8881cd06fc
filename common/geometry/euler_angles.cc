#include "common/geometry/euler_angles.h"
#include "common/geometry/angles.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace tiltcal::geometry {

Eigen::Matrix3d RotX(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
}
Eigen::Matrix3d RotY(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
}
Eigen::Matrix3d RotZ(double a) {
  return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

Eigen::Matrix3d RotationFromEuler123(const Eigen::Vector3d& angles_rad) {
  return RotZ(angles_rad.z()) * RotY(angles_rad.y()) * RotX(angles_rad.x());
}

Eigen::Matrix3d RotationFromEuler123Deg(const Eigen::Vector3d& angles_deg) {
  return RotationFromEuler123(angles_deg * kRadPerDeg);
}

Eigen::Vector3d Euler123FromRotation(const Eigen::Matrix3d& c) {
  // C = Rz(c3) Ry(c2) Rx(c1):
  //   C(2,0) = -sin θ2,  C(2,1) = cos θ2 sin θ1,  C(2,2) = cos θ2 cos θ1,
  //   C(1,0) = cos θ2 sin θ3,  C(0,0) = cos θ2 cos θ3.
  const double sin_pitch = std::clamp(-c(2, 0), -1.0, 1.0);
  const double cos_pitch = std::hypot(c(0, 0), c(1, 0));
  const double pitch = std::atan2(sin_pitch, cos_pitch);
  if (cos_pitch < 1e-9) {
    // Gimbal lock: only θ3 ∓ θ1 is defined; choose θ1 = 0.
    return {0.0, pitch, std::atan2(-c(0, 1), c(1, 1))};
  }
  return {std::atan2(c(2, 1), c(2, 2)), pitch, std::atan2(c(1, 0), c(0, 0))};
}

}  // namespace tiltcal::geometry
