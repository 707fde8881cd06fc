#ifndef TILTCAL_COMMON_CALIBRATION_CALIBRATION_CHECKS_H_
#define TILTCAL_COMMON_CALIBRATION_CALIBRATION_CHECKS_H_

// What a calibration must hold before its extrinsic and covariance are
// used (proto::SequenceInputParams): by tiltcal_dataset_calibration before
// it fuses a sequence, by tiltcal_verify for the reference and each
// sequence's estimate: every number the fusion reads finite, the
// quaternions of imu_from_lidar and rig_imu_from_lidar unit within
// max_quaternion_norm_error, tau sigma >= 0, and the fused block of the
// covariance (6x6: rotation [rad] and translation [m]; 7x7 with tau [s] when
// the clocks are shared) symmetric within max_covariance_asymmetry (largest
// |P_ij - P_ji| over the largest |P_ij|) and positive definite, with every
// sigma = sqrt(eigenvalue) within [min_sigma, max_sigma] and the condition
// number (largest over smallest eigenvalue) at most max_condition_number.

#include <string>

#include "common/status.h"
#include "tiltcal/proto/calibration.pb.h"
#include "tiltcal/proto/dataset_params.pb.h"

namespace tiltcal::calibration {

// min_sigma < max_sigma (what the schema's bounds cannot say).
Status ValidateSequenceInputParams(const proto::SequenceInputParams& params);

// Why `result` cannot be fused with a block of size n (6 or 7), naming the
// field and its value; "" when it can.
std::string ReasonRefused(const proto::CalibrationResult& result, int n,
                          const proto::SequenceInputParams& params);

}  // namespace tiltcal::calibration

#endif  // TILTCAL_COMMON_CALIBRATION_CALIBRATION_CHECKS_H_
