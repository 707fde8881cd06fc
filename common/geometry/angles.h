#ifndef TILTCAL_COMMON_GEOMETRY_ANGLES_H_
#define TILTCAL_COMMON_GEOMETRY_ANGLES_H_

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tiltcal::geometry {

// Degrees <-> radians. The constants are 180/π and π/180 rounded once to a
// double; a value times a constant is `x * (180/π)`. The functions evaluate
// `(x * 180) / π` and `(x * π) / 180`, bit for bit what the inline
// `x * 180.0 / M_PI` and `x * M_PI / 180.0` gave, so results written before
// this header existed are reproduced exactly. The two forms may differ in the
// last bit (about 1e-16 relative).
inline constexpr double kDegPerRad = 180.0 / M_PI;  // deg per rad
inline constexpr double kRadPerDeg = M_PI / 180.0;  // rad per deg
inline constexpr double kTwoPi = 2.0 * M_PI;       // rad per turn

constexpr double RadToDeg(double angle_rad) { return angle_rad * 180.0 / M_PI; }
constexpr double DegToRad(double angle_deg) { return angle_deg * M_PI / 180.0; }

// Per component, for angle triples (Euler angles, rotation vectors).
inline Eigen::Vector3d RadToDeg(const Eigen::Vector3d& angles_rad) {
  return angles_rad * 180.0 / M_PI;
}
inline Eigen::Vector3d DegToRad(const Eigen::Vector3d& angles_deg) {
  return angles_deg * M_PI / 180.0;
}

// Angle between two non-zero vectors, deg in [0, 180]:
// atan2(|a × b|, a · b), accurate at every angle (acos of the normalised dot
// product loses precision near 0 and 180 deg).
inline double AngleBetweenDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDegPerRad;
}

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_ANGLES_H_
