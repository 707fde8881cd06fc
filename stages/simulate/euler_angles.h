#ifndef TILTCAL_STAGES_SIMULATE_EULER_ANGLES_H_
#define TILTCAL_STAGES_SIMULATE_EULER_ANGLES_H_

#include <Eigen/Core>

namespace tiltcal::simulate {

// Rotation from Euler angles (roll, pitch, yaw) in degrees:
//   C = Rz(yaw) * Ry(pitch) * Rx(roll)
// with R*(θ) the active rotations about the fixed axes. The Husky rig's
// C_bl = [180, 0, -90] deg maps the LiDAR's z axis to the IMU's −z.
Eigen::Matrix3d RotationFromEulerDeg(const Eigen::Vector3d& roll_pitch_yaw_deg);

// Inverse of RotationFromEulerDeg (pitch in [−90, 90] deg).
Eigen::Vector3d EulerDegFromRotation(const Eigen::Matrix3d& rotation);

// Active rotations about the x, y and z axes by `angle_rad`.
Eigen::Matrix3d RotX(double angle_rad);
Eigen::Matrix3d RotY(double angle_rad);
Eigen::Matrix3d RotZ(double angle_rad);

}  // namespace tiltcal::simulate

#endif  // TILTCAL_STAGES_SIMULATE_EULER_ANGLES_H_
