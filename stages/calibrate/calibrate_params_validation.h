#ifndef TILTCAL_STAGES_CALIBRATE_CALIBRATE_PARAMS_VALIDATION_H_
#define TILTCAL_STAGES_CALIBRATE_CALIBRATE_PARAMS_VALIDATION_H_

// The rules on CalibrateParams that the schema bounds
// (proto/tiltcal/proto/calibrate_params.proto, checked by common/io/params.h)
// cannot express: strictly positive values where the bound is an inclusive 0,
// and relations between fields. One function per message that has such
// rules; each error names the field by its dotted path from CalibrateParams.
// ValidateCalibrateParams runs them all; LoadCalibrateParams runs it once,
// after the schema bounds, when the params are loaded.

#include <string>

#include "common/status.h"
#include "tiltcal/proto/calibrate_params.pb.h"

namespace tiltcal::calibrate {

Status ValidateImuNoiseParams(const proto::ImuNoiseParams& params);
Status ValidateLidarScanParams(const proto::LidarScanParams& params);
Status ValidateLidarResidualParams(const proto::LidarResidualParams& params);
Status ValidateInitParams(const proto::InitParams& params);
// `path` names the message in the errors ("map", "odometry.quality_map").
Status ValidateSurfelMapParams(const proto::SurfelMapParams& params, const std::string& path);
// odometry.quality_map, and odometry.voxel_icp when the method is VOXEL_ICP.
Status ValidateLidarOdometryParams(const proto::LidarOdometryParams& params);
Status ValidateAssociationParams(const proto::AssociationParams& params, const std::string& name);
Status ValidateGroundResidualsParams(const proto::GroundResidualsParams& params);
Status ValidateVerdictParams(const proto::VerdictParams& params);
Status ValidateImuVibrationParams(const proto::ImuVibrationParams& params);
Status ValidateObservabilityParams(const proto::ObservabilityParams& params);

Status ValidateCalibrateParams(const proto::CalibrateParams& params);

// The params file at `path` (or, when `path` is empty, the stage's defaults,
// DefaultParamsText()), checked against the schema bounds and by
// ValidateCalibrateParams.
Status LoadCalibrateParams(const std::string& path, proto::CalibrateParams* params);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_CALIBRATE_PARAMS_VALIDATION_H_
