#ifndef TILTCAL_STAGES_DECODE_DECODE_PARAMS_H_
#define TILTCAL_STAGES_DECODE_DECODE_PARAMS_H_

#include "common/status.h"
#include "tiltcal/proto/decode_params.pb.h"

namespace tiltcal::decode {

// The rules of the decode params that the schema bounds
// (proto/tiltcal/proto/decode_params.proto) cannot express, one function per
// message. Each error names the field by its path in DecodeParams.

// accel_norm_ratio_max > accel_norm_ratio_min.
Status ValidateImuUnitsParams(const proto::ImuUnitsParams& imu_units);

// The schema bounds of every field, then the rules above.
Status ValidateDecodeParams(const proto::DecodeParams& params);

}  // namespace tiltcal::decode

#endif  // TILTCAL_STAGES_DECODE_DECODE_PARAMS_H_
