#ifndef TILTCAL_STAGES_CALIBRATE_INIT_ROTATION_FROM_MOTION_H_
#define TILTCAL_STAGES_CALIBRATE_INIT_ROTATION_FROM_MOTION_H_

// The extrinsic rotation C_bl found from the motion alone, from any
// starting guess or none (docs/design.md §9, "The starting extrinsic"):
//  - the LiDAR odometry (every rotation_search.scan_step-th scan; in the
//    first round on raw scans and without a gyro prior, which a wrong guess
//    would turn the wrong way; afterwards deskewed and given the prior with
//    the current C_bl) and the coarse tau;
//  - when the motion turns about more than one axis (hand-eye excitation),
//    the hand-eye rotation;
//  - otherwise (planar motion) two steps: the smallest rotation that maps
//    the LiDAR's principal rotation axis onto the IMU's (any angle: an
//    upside-down sensor is a 180 deg turn), then the rotation about that
//    axis from the accelerations (rig_rotation_check.h): the LiDAR's
//    accelerations, mapped by C_bl, turned onto the IMU's;
// repeated with the odometry rerun at the new C_bl until a round changes
// C_bl by less than rotation_search.converged_deg. The calibration then
// starts from the result (initialisation.h), which is within a degree or so.

#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "common/imu/imu_reading.h"
#include "common/status.h"
#include "stages/calibrate/init/hand_eye_rotation.h"
#include "stages/calibrate/init/rig_rotation_check.h"
#include "stages/calibrate/problem/lidar_scans.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

// One round of the search.
struct RotationSearchRound {
  bool gyro_aided = false;       // the odometry deskewed and predicted with the gyro
  bool from_hand_eye = false;    // C_bl from hand-eye (else axes + accelerations)
  double axis_turn_deg = 0.0;    // rotation that aligned the principal axes
  AccelerationCheck acceleration;  // the check after the axis alignment
  double change_deg = 0.0;       // C_bl of this round against the previous one
};

struct RotationFromMotion {
  Eigen::Quaterniond imu_from_lidar = Eigen::Quaterniond::Identity();  // C_bl found
  // The rotation about the motion's axis came from the accelerations (or
  // hand-eye); false: it stayed the guess's (accelerations too small).
  bool about_axis_decided = false;
  Eigen::Vector3d axis_b = Eigen::Vector3d::UnitZ();  // the motion's principal axis, frame b
  double time_offset_s = 0.0;                         // the coarse tau of the last round
  TurningAmount turning;
  HandEyeResult hand_eye;  // of the last round
  std::vector<RotationSearchRound> rounds;
  double seconds = 0.0;
};

// Finds C_bl from the IMU samples (times relative to the first sample) and
// the raw scans, starting from `guess` (the rig's or /tf_static's C_bl;
// nullopt: none). `translation_guess` is the lever arm r_b^{lb} used by the
// acceleration check (zero when unknown: the check then ignores the lever
// arm's centripetal accelerations). Errors: too little turning
// (MissingTurning), no guess and accelerations too small to decide the
// rotation about the motion's axis (the line names both and what to record)
// — both Status::NotDetermined: the motion cannot decide — and no settling
// within rotation_search.max_rounds.
Status FindImuFromLidarRotation(const std::vector<imu::ImuReading>& imu_samples,
                                const std::vector<LidarScan>& scans,
                                const std::optional<Eigen::Quaterniond>& guess,
                                const Eigen::Vector3d& translation_guess,
                                const proto::CalibrateParams& params, RotationFromMotion* result);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_INIT_ROTATION_FROM_MOTION_H_
