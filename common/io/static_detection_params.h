#ifndef TILTCAL_COMMON_IO_STATIC_DETECTION_PARAMS_H_
#define TILTCAL_COMMON_IO_STATIC_DETECTION_PARAMS_H_

#include "common/imu/static_detection.h"
#include "tiltcal/proto/static_detection_params.pb.h"

namespace tiltcal {

// The options of common/imu's static detection from a stage's params block.
imu::StaticDetectionOptions ToStaticDetectionOptions(const proto::StaticDetectionParams& params);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_STATIC_DETECTION_PARAMS_H_
