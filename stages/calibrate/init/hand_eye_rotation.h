#ifndef TILTCAL_STAGES_CALIBRATE_INIT_HAND_EYE_ROTATION_H_
#define TILTCAL_STAGES_CALIBRATE_INIT_HAND_EYE_ROTATION_H_

// Rotation-only hand-eye calibration C_bl from paired relative rotations of
// the IMU (gyro integration) and the LiDAR (odometry), with an excitation
// measure so the caller keeps the rig's measured C_bl when the motion is
// (nearly) about one axis, as for a ground vehicle on a plane.
//
// Model: for two times i, j the relative rotations satisfy
//   C_{b_i b_j} = C_bl C_{l_i l_j} C_bl^T   <=>   q_b (x) q_bl = q_bl (x) q_l,
// with Hamilton quaternions q_b = q(C_{b_i b_j}), q_l = q(C_{l_i l_j}),
// q_bl = q(C_bl). Stacking (L(q_b) - R(q_l)) q_bl = 0 (L, R: left/right
// quaternion product matrices) with weights h gives A q_bl = 0, solved by the
// right singular vector of A's smallest singular value.
//
// Excitation: one pair about axis u leaves a 2-D null space (any rotation
// about u composed with the truth); rotations about one axis only keep it
// 2-D, so the third singular value s[2] (of four, descending) collapses.
// excitation_rad = s[2] / sqrt(sum h^2) ~ the RMS angle (rad) of rotation
// perpendicular to the worst-excited direction. OA-Calib's test is the raw
// s[2] > 0.25 with >= 15 pairs.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

struct RotationPair {
  Eigen::Quaterniond imu_delta = Eigen::Quaterniond::Identity();    // C_{b_i b_j}
  Eigen::Quaterniond lidar_delta = Eigen::Quaterniond::Identity();  // C_{l_i l_j}
};

struct HandEyeResult {
  bool solved = false;    // enough pairs, SVD done
  bool excited = false;   // solved and excitation_rad >= params.min_excitation_rad: use it
  Eigen::Quaterniond imu_from_lidar_rotation = Eigen::Quaterniond::Identity();  // C_bl
  Eigen::Vector4d singular_values = Eigen::Vector4d::Zero();  // of A, descending
  double excitation_rad = 0.0;       // s[2] / sqrt(sum h^2)
  double excitation_ratio = 0.0;     // s[2] / s[0] (scale-free)
  // sqrt of the eigenvalues (descending) of mean(phi phi^T), phi = Log(C_{b_i b_j}):
  // RMS rotation about the principal axes of the motion, rad.
  Eigen::Vector3d rotation_spread_rad = Eigen::Vector3d::Zero();
  // RMS over pairs of |Log(C_bl C_l C_bl^T C_b^T)| for the estimate, deg.
  double rms_residual_deg = 0.0;
  int num_pairs = 0;
};

// Solved with at least params.min_pairs pairs; a pair whose IMU and LiDAR
// rotation angles differ by more than params.consistent_angle_deg gets weight
// 1 / (difference in deg) instead of 1 (OA-Calib: 1 deg); excited when
// excitation_rad >= params.min_excitation_rad.
HandEyeResult EstimateHandEyeRotation(const std::vector<RotationPair>& pairs,
                                      const proto::HandEyeParams& params);

// Pairs (k, k + step) for k = 0, step, 2 step, ... from absolute rotations of
// the same instants: imu_rotations[k] = C_ab(t_k), lidar_rotations[k] =
// C_{l_0 l_k}. Sizes must match.
std::vector<RotationPair> MakeRotationPairs(const std::vector<Eigen::Quaterniond>& imu_rotations,
                                            const std::vector<Eigen::Quaterniond>& lidar_rotations,
                                            int step);

// The rotation the calibrator starts from: the estimate when excited, else
// the rig's measured C_bl (the paper's protocol).
Eigen::Quaterniond ChooseInitialRotation(const Eigen::Quaterniond& measured_imu_from_lidar,
                                         const HandEyeResult& result);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_INIT_HAND_EYE_ROTATION_H_
