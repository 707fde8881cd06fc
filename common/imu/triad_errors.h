#ifndef TILTCAL_COMMON_IMU_TRIAD_ERRORS_H_
#define TILTCAL_COMMON_IMU_TRIAD_ERRORS_H_

// The scale and axis errors of one IMU sensor triad (docs/design.md §6,
// "IMU intrinsics"):
//   measured = (I + E) true,
// `true` the angular rate or specific force resolved in the IMU frame b, E a
// 3x3 matrix stored row-major in kTriadErrorsSize doubles (the calibrator's
// parameter block; E = 0: an ideal triad). E's diagonal are the scale
// errors (fractions), its off-diagonal entries the axis misalignments
// (small angles, rad): row i of I + E is the sensing direction of sensor i
// in b. A triad whose E is lower triangular has its x axis on b's x axis and
// its y axis in b's x-y plane, i.e. it defines frame b.
//
// E multiplies the predicted reading, not the measured one: a correction
// applied to the measurement would scale its noise too, and where the motion
// excites an axis little (a ground vehicle's roll rate) shrinking that axis's
// noise would pull the estimate away from the truth.

#include <Eigen/Core>

namespace tiltcal::imu {

inline constexpr int kTriadErrorsSize = 9;

// E from its kTriadErrorsSize doubles (row-major).
inline Eigen::Matrix3d TriadErrorsMatrix(const double* e) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(e);
}

// d(E v)/d(E's doubles) = [v^T 0 0; 0 v^T 0; 0 0 v^T] (3 x 9) for the
// predicted reading v.
inline Eigen::Matrix<double, 3, kTriadErrorsSize> TriadErrorsJacobian(const Eigen::Vector3d& v) {
  Eigen::Matrix<double, 3, kTriadErrorsSize> j = Eigen::Matrix<double, 3, kTriadErrorsSize>::Zero();
  for (int i = 0; i < 3; ++i) j.block<1, 3>(i, 3 * i) = v.transpose();
  return j;
}

}  // namespace tiltcal::imu

#endif  // TILTCAL_COMMON_IMU_TRIAD_ERRORS_H_
