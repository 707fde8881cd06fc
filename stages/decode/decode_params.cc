#include "stages/decode/decode_params.h"

#include "common/io/params.h"

namespace tiltcal::decode {

Status ValidateImuUnitsParams(const proto::ImuUnitsParams& imu_units) {
  if (!(imu_units.accel_norm_ratio_max() > imu_units.accel_norm_ratio_min())) {
    return Status::Error(
        "field imu_units.accel_norm_ratio_max must be greater than "
        "imu_units.accel_norm_ratio_min");
  }
  return Status::Ok();
}

Status ValidateDecodeParams(const proto::DecodeParams& params) {
  TILTCAL_RETURN_IF_ERROR(ValidateAgainstSchema(params));
  return ValidateImuUnitsParams(params.imu_units());
}

}  // namespace tiltcal::decode
