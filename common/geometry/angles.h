#ifndef TILTCAL_COMMON_GEOMETRY_ANGLES_H_
#define TILTCAL_COMMON_GEOMETRY_ANGLES_H_

#include <cmath>

#include <Eigen/Core>

namespace tiltcal::geometry {

// Degrees <-> radians. The constants are 180/π and π/180 rounded once to a
// double; a value times a constant is `x * (180/π)`. The functions evaluate
// `(x * 180) / π` and `(x * π) / 180`, bit for bit what the inline
// `x * 180.0 / M_PI` and `x * M_PI / 180.0` gave, so results written before
// this header existed are reproduced exactly. The two forms may differ in the
// last bit (about 1e-16 relative).
inline constexpr double kDegPerRad = 180.0 / M_PI;  // deg per rad
inline constexpr double kRadPerDeg = M_PI / 180.0;  // rad per deg

constexpr double RadToDeg(double angle_rad) { return angle_rad * 180.0 / M_PI; }
constexpr double DegToRad(double angle_deg) { return angle_deg * M_PI / 180.0; }

// Per component, for angle triples (Euler angles, rotation vectors).
inline Eigen::Vector3d RadToDeg(const Eigen::Vector3d& angles_rad) {
  return angles_rad * 180.0 / M_PI;
}
inline Eigen::Vector3d DegToRad(const Eigen::Vector3d& angles_deg) {
  return angles_deg * M_PI / 180.0;
}

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_ANGLES_H_
