#ifndef TILTCAL_STAGES_CALIBRATE_INIT_RIG_ROTATION_CHECK_H_
#define TILTCAL_STAGES_CALIBRATE_INIT_RIG_ROTATION_CHECK_H_

// Checks of the rig's extrinsic rotation C_bl against what the motion shows
// (docs/design.md §9), for a rig rotation wrong by up to 180 deg (a yaw off
// by 90 deg, an IMU mounted upside down and not declared):
//  - axes: the principal rotation axis of the LiDAR's relative rotations,
//    mapped into b by C_bl, against the IMU's. Sees an error that tilts the
//    axis (upside down: anti-parallel, 180 deg); blind to a rotation about
//    the axis itself (planar motion).
//  - accelerations: about the axis, the LiDAR odometry's accelerations
//    mapped into b by C_bl against the IMU's. A vehicle accelerates forward
//    and sideways (in turns); a yaw error of C_bl turns the one into the
//    other (90 deg swaps them).

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/imu/imu_reading.h"
#include "stages/calibrate/init/hand_eye_rotation.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

// Principal axes (dominant eigenvectors of sum phi phi^T, phi = Log of the
// relative rotation) of the IMU's (frame b) and the LiDAR's (frame l)
// relative rotations, the LiDAR's sign chosen so that the two rotation
// angles about them correlate positively. False without rotation.
bool MatchedPrincipalAxes(const std::vector<RotationPair>& pairs, Eigen::Vector3d* axis_b,
                          Eigen::Vector3d* axis_l);

// Angle between C_bl a_l and a_b (MatchedPrincipalAxes), deg in [0, 180];
// 0 without rotation.
double RotationAxisDisagreementDeg(const std::vector<RotationPair>& pairs,
                                   const Eigen::Quaterniond& imu_from_lidar);

// How much the vehicle turned, from the IMU's relative rotations of the
// rotation pairs (consecutive, non-overlapping): s_k = phi_k . a_b with
// phi_k = Log(C_{b_i b_j}) and a_b the principal axis (MatchedPrincipalAxes).
struct TurningAmount {
  int pairs = 0;
  double span_s = 0.0;             // LiDAR time from the first pair's start to the last's end
  double rms_about_axis_rad = 0.0;  // sqrt(mean s_k^2)
  double left_rad = 0.0;            // sum of max(s_k, 0): turning one way about a_b
  double right_rad = 0.0;           // sum of max(-s_k, 0): the other way
};

// The turning of `pairs`; span_s from `pair_times_s` (start and end LiDAR
// time of each pair, same order; empty: 0).
TurningAmount MeasureTurning(const std::vector<RotationPair>& pairs,
                             const std::vector<std::pair<double, double>>& pair_times_s);

// Empty when the turning decides the motion's rotation axis (rms_about_axis_rad
// at least params.min_axis_rotation_rad); else the line that says what the
// motion lacks, with the measured and the needed amounts and what to record.
std::string MissingTurning(const TurningAmount& turning, const proto::InitParams& params);

struct AccelerationCheck {
  bool decided = false;  // enough horizontal acceleration to tell
  // Signed angle about axis_b of the rotation that best maps the LiDAR's
  // accelerations (through C_bl) onto the IMU's, deg in (-180, 180].
  double yaw_error_deg = 0.0;
  double rms_horizontal_acceleration_mps2 = 0.0;  // IMU side, perpendicular to the axis
  int samples = 0;
};

// With h = params.acceleration_check_half_window_s, for each odometry pose k
// (LiDAR time t_k, position r_{l0}^{lk l0}; pose 0 defines l0) with
// [t_k - h, t_k + h] inside the poses' span:
//   LiDAR:  w_k = C_bl (p(t_k + h) - 2 p(t_k) + p(t_k - h)) / h^2   (p linear
//           between poses; frame b at pose 0),
//   IMU:    u_k = C_ab(t_0 + tau)^T (K_h * (C_ab f_m + g_a)(t_k + tau)
//           + (q(t_k+tau+h) - 2 q(t_k+tau) + q(t_k+tau-h)) / h^2),
//           q = C_ab r_b^{lb} (the lever arm), K_h the triangle kernel of
//           half-width h (the second difference is the acceleration under
//           that kernel),
// from the state's rotation spline, g_a, tau, C_bl, r_b^{lb}; the yaw error
// is atan2(sum a.(w_perp x u_perp), sum w_perp.u_perp) over the components
// perpendicular to axis_b. Decided when the RMS |u_perp| is at least
// params.min_check_acceleration_mps2.
AccelerationCheck CheckRigYawByAccelerations(const CalibrationState& state,
                                             const std::vector<imu::ImuReading>& imu_samples,
                                             const std::vector<double>& lidar_times_s,
                                             const std::vector<Eigen::Vector3d>& lidar_positions_l0,
                                             const Eigen::Vector3d& axis_b,
                                             const proto::InitParams& params);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_INIT_RIG_ROTATION_CHECK_H_
