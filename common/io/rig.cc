#include "common/io/rig.h"

#include <cmath>

#include <fmt/format.h>

#include "common/io/eigen_proto.h"
#include "common/io/text_proto.h"

namespace tiltcal {

namespace {

bool IsFinite(const proto::Vector3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

// Text format accepts any number for a proto3 enum; only the named values
// mean a unit.
Status CheckUnits(const proto::Rig& rig) {
  if (!proto::AccelUnit::Unit_IsValid(rig.imu_accel_unit())) {
    return Status::Error(fmt::format("imu_accel_unit = {} is not one of AUTO, MPS2, G",
                                     static_cast<int>(rig.imu_accel_unit())));
  }
  if (!proto::GyroUnit::Unit_IsValid(rig.imu_gyro_unit())) {
    return Status::Error(fmt::format("imu_gyro_unit = {} is not one of AUTO, RADPS, DEGPS",
                                     static_cast<int>(rig.imu_gyro_unit())));
  }
  return Status::Ok();
}

}  // namespace

Status ValidateImuFromLidar(bool present, proto::Rigid3* imu_from_lidar,
                            const std::string& field) {
  if (!present || !imu_from_lidar->has_rotation()) {
    return Status::Error(field + ".rotation is missing (the extrinsic C_bl)");
  }
  proto::Quaternion* q = imu_from_lidar->mutable_rotation();
  const double norm = std::sqrt(q->w() * q->w() + q->x() * q->x() + q->y() * q->y() +
                                q->z() * q->z());
  if (!std::isfinite(norm)) return Status::Error(field + ".rotation is not finite");
  if (std::fabs(norm - 1.0) > kRigQuaternionNormTolerance) {
    return Status::Error(fmt::format(
        "{}.rotation is not a unit quaternion (norm {:.6g}; w x y z, Hamilton)", field, norm));
  }
  *q = ToProto(ToEigen(*q));
  const proto::Vector3& translation = imu_from_lidar->translation();
  if (!IsFinite(translation)) return Status::Error(field + ".translation is not finite");
  const double distance = ToEigen(translation).norm();
  if (distance > kRigMaxTranslationM) {
    return Status::Error(fmt::format(
        "{}.translation is {:.3g} m long, more than {} m (metres, IMU frame)", field, distance,
        kRigMaxTranslationM));
  }
  return Status::Ok();
}

Status ValidateRig(proto::Rig* rig) {
  if (rig->has_imu_from_lidar()) {
    TILTCAL_RETURN_IF_ERROR(ValidateImuFromLidar(true, rig->mutable_imu_from_lidar(),
                                                 "imu_from_lidar"));
  }
  if (rig->has_starting_extrinsic() && rig->starting_extrinsic().has_guess()) {
    TILTCAL_RETURN_IF_ERROR(ValidateImuFromLidar(
        true, rig->mutable_starting_extrinsic()->mutable_guess(), "starting_extrinsic.guess"));
  }
  if (!std::isfinite(rig->imu_height_m()) || rig->imu_height_m() < 0 ||
      rig->imu_height_m() > kRigMaxImuHeightM) {
    return Status::Error(fmt::format("imu_height_m = {} is outside [0, {}] m (0 = unknown)",
                                     rig->imu_height_m(), kRigMaxImuHeightM));
  }
  if (rig->has_gravity_flat_in_imu() && ToEigen(rig->gravity_flat_in_imu()).norm() != 0.0) {
    TILTCAL_RETURN_IF_ERROR(ValidateGravityFlat(rig->gravity_flat_in_imu(), "gravity_flat_in_imu"));
  }
  return CheckUnits(*rig);
}

Status ValidateGravityFlat(const proto::Vector3& gravity, const std::string& field) {
  if (!IsFinite(gravity)) return Status::Error(field + " is not finite");
  const double g = ToEigen(gravity).norm();
  if (g < kRigMinGravityMps2 || g > kRigMaxGravityMps2) {
    return Status::Error(fmt::format("{} has norm {:.4g}, not a gravity in m/s² (expected {} to {})",
                                     field, g, kRigMinGravityMps2, kRigMaxGravityMps2));
  }
  return Status::Ok();
}

Status LoadRig(const std::string& path, proto::Rig* rig) {
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(path, rig));
  return ValidateRig(rig).WithContext(path);
}

Status LoadRigWithExtrinsic(const std::string& path, proto::Rig* rig) {
  TILTCAL_RETURN_IF_ERROR(LoadRig(path, rig));
  if (rig->has_imu_from_lidar()) return Status::Ok();
  return Status::Error(
             "imu_from_lidar.rotation is missing (the extrinsic C_bl): give this stage the "
             "sequence's rig that tiltcal_initial_extrinsic writes (out/<sequence>/rig.txtpb), "
             "which has the rotation found from the motion")
      .WithContext(path);
}

}  // namespace tiltcal
