#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_TYPE_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_TYPE_H_

// The sensor a residual block of the calibration problem measures, by its
// cost function: gyro (GyroCostFunction), accel (AccelCostFunction), lidar
// (PointToPlaneCostFunction), ground (the four residuals of
// ground_cost_functions.h); everything else (bias random walks, priors) is
// other. A stacked block has its rows' type, a drifting-time-offset block its
// inner residual's.
//
// Its variance group (variance_components.h) is its type, with the ground
// split by residual (flat, dist, incl, up): the four measure different
// quantities of the same plane fits (the normal's direction, the LiDAR's
// height), whose errors differ in size and in how long they stay correlated
// along the sequence (docs/design.md §11).

#include <ceres/cost_function.h>

namespace tiltcal::calibrate {

enum ResidualType { kGyro = 0, kAccel, kLidar, kGround, kOther };
constexpr int kNumResidualTypes = kOther + 1;

ResidualType TypeOf(const ceres::CostFunction* f);

// "gyro", "accel", "lidar", "ground", "other".
const char* ResidualTypeName(ResidualType type);

enum VarianceGroup {
  kGyroGroup = 0,
  kAccelGroup,
  kLidarGroup,
  kGroundFlatGroup,
  kGroundDistGroup,
  kGroundInclGroup,
  kGroundUpGroup,
  kOtherGroup
};
constexpr int kNumVarianceGroups = kOtherGroup + 1;

VarianceGroup VarianceGroupOf(const ceres::CostFunction* f);
ResidualType TypeOfGroup(VarianceGroup group);

// "gyro", "accel", "lidar", "ground flat", "ground dist", "ground incl",
// "ground up", "other".
const char* VarianceGroupName(VarianceGroup group);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_TYPE_H_
