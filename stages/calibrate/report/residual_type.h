#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_TYPE_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_TYPE_H_

// The sensor a residual block of the calibration problem measures, by its
// cost function: gyro (GyroCostFunction), accel (AccelCostFunction), lidar
// (PointToPlaneCostFunction), ground (the four residuals of
// ground_cost_functions.h); everything else (bias random walks, priors) is
// other. A stacked block has its rows' type, a drifting-time-offset block its
// inner residual's.

#include <ceres/cost_function.h>

namespace tiltcal::calibrate {

enum ResidualType { kGyro = 0, kAccel, kLidar, kGround, kOther };
constexpr int kNumResidualTypes = kOther + 1;

ResidualType TypeOf(const ceres::CostFunction* f);

// "gyro", "accel", "lidar", "ground", "other".
const char* ResidualTypeName(ResidualType type);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_TYPE_H_
