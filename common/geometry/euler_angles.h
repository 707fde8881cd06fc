#ifndef TILTCAL_COMMON_GEOMETRY_EULER_ANGLES_H_
#define TILTCAL_COMMON_GEOMETRY_EULER_ANGLES_H_

#include <Eigen/Core>

namespace tiltcal::geometry {

// 1-2-3 Euler angles (θ1, θ2, θ3) in radians, the convention of the tables of
// the paper and of rig presets such as the Husky's [180, 0, -90] deg:
//   C = R_z(θ3) R_y(θ2) R_x(θ1),
// with R_k the active rotation about axis k (rotate about x first, then y,
// then z, about fixed axes; roll, pitch, yaw). θ2 is in [-π/2, π/2]; θ1 and θ3
// in (-π, π]. At θ2 = ±π/2 (gimbal lock) θ1 is set to 0.
Eigen::Matrix3d RotationFromEuler123(const Eigen::Vector3d& angles_rad);
Eigen::Vector3d Euler123FromRotation(const Eigen::Matrix3d& rotation);
// The same with angles in degrees (rig presets and params are in degrees).
Eigen::Matrix3d RotationFromEuler123Deg(const Eigen::Vector3d& angles_deg);

// Active rotations about the x, y and z axes by `angle_rad`.
Eigen::Matrix3d RotX(double angle_rad);
Eigen::Matrix3d RotY(double angle_rad);
Eigen::Matrix3d RotZ(double angle_rad);

}  // namespace tiltcal::geometry

#endif  // TILTCAL_COMMON_GEOMETRY_EULER_ANGLES_H_
