#ifndef TILTCAL_COMMON_IO_RIG_H_
#define TILTCAL_COMMON_IO_RIG_H_

#include <string>

#include "common/status.h"
#include "tiltcal/proto/rig.pb.h"

namespace tiltcal {

// How far the norm of the rig's rotation quaternion may be from 1 (a
// hand-written quaternion with four decimals is off by ~1e-4).
inline constexpr double kRigQuaternionNormTolerance = 1e-3;
// Bounds of a plausible rig: the LiDAR within 10 m of the IMU, the IMU at
// most 10 m above the ground, g_f between 8.5 and 11 m/s² when given.
inline constexpr double kRigMaxTranslationM = 10.0;
inline constexpr double kRigMaxImuHeightM = 10.0;
inline constexpr double kRigMinGravityMps2 = 8.5;
inline constexpr double kRigMaxGravityMps2 = 11.0;

// Checks an extrinsic (C_bl, r_b^{lb}) read from a file: present, every
// value finite, a unit quaternion within kRigQuaternionNormTolerance
// (normalised in place), a translation at most kRigMaxTranslationM long.
// The error names the field by `field` ("imu_from_lidar").
Status ValidateImuFromLidar(bool present, proto::Rigid3* imu_from_lidar,
                            const std::string& field);

// Checks a gravity read from a file (g_f in the IMU frame, m/s²): finite,
// its norm within [kRigMinGravityMps2, kRigMaxGravityMps2]. The error names
// `field`.
Status ValidateGravityFlat(const proto::Vector3& gravity, const std::string& field);

// Checks a rig (the dataset's rig.txtpb): imu_from_lidar, when present
// (tiltcal_initial_extrinsic finds it from the motion otherwise), with a unit
// quaternion (within kRigQuaternionNormTolerance; normalised in place),
// every value finite, the translation, imu_height_m and gravity_flat_in_imu
// (when set) within the bounds above, imu_accel_unit and imu_gyro_unit
// named values of their enums. The error names the field.
Status ValidateRig(proto::Rig* rig);

// Reads rig.txtpb (a regular, non-empty file) and validates it; every error
// names the file and the field. Every stage reads the rig through this.
Status LoadRig(const std::string& path, proto::Rig* rig);

// LoadRig for the stages that need the extrinsic (ground, gravity,
// calibrate): imu_from_lidar must be present. They read the sequence's rig
// that tiltcal_initial_extrinsic writes (out/<sequence>/rig.txtpb), which
// always has it.
Status LoadRigWithExtrinsic(const std::string& path, proto::Rig* rig);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_RIG_H_
