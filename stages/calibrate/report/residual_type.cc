#include "stages/calibrate/report/residual_type.h"

#include "stages/calibrate/residuals/accel_cost_function.h"
#include "stages/calibrate/residuals/drifting_time_offset_cost_function.h"
#include "stages/calibrate/residuals/ground_cost_functions.h"
#include "stages/calibrate/residuals/gyro_cost_function.h"
#include "stages/calibrate/residuals/point_to_plane_cost_function.h"
#include "stages/calibrate/residuals/stacked_cost_function.h"

namespace tiltcal::calibrate {

VarianceGroup VarianceGroupOf(const ceres::CostFunction* f) {
  if (const auto* stacked = dynamic_cast<const StackedCostFunction*>(f)) {
    return VarianceGroupOf(&stacked->row(0));
  }
  if (const auto* drifting = dynamic_cast<const DriftingTimeOffsetCostFunction*>(f)) {
    return VarianceGroupOf(&drifting->inner());
  }
  if (dynamic_cast<const GyroCostFunction*>(f) != nullptr) return kGyroGroup;
  if (dynamic_cast<const AccelCostFunction*>(f) != nullptr) return kAccelGroup;
  if (dynamic_cast<const PointToPlaneCostFunction*>(f) != nullptr) return kLidarGroup;
  if (dynamic_cast<const FlatGroundCostFunction*>(f) != nullptr) return kGroundFlatGroup;
  if (dynamic_cast<const DistanceCostFunction*>(f) != nullptr) return kGroundDistGroup;
  if (dynamic_cast<const InclinationCostFunction*>(f) != nullptr) return kGroundInclGroup;
  if (dynamic_cast<const UpCostFunction*>(f) != nullptr) return kGroundUpGroup;
  return kOtherGroup;
}

ResidualType TypeOfGroup(VarianceGroup group) {
  switch (group) {
    case kGyroGroup: return kGyro;
    case kAccelGroup: return kAccel;
    case kLidarGroup: return kLidar;
    case kGroundFlatGroup:
    case kGroundDistGroup:
    case kGroundInclGroup:
    case kGroundUpGroup: return kGround;
    case kOtherGroup: return kOther;
  }
  return kOther;
}

ResidualType TypeOf(const ceres::CostFunction* f) { return TypeOfGroup(VarianceGroupOf(f)); }

const char* ResidualTypeName(ResidualType type) {
  constexpr const char* kNames[] = {"gyro", "accel", "lidar", "ground", "other"};
  return kNames[type];
}

const char* VarianceGroupName(VarianceGroup group) {
  constexpr const char* kNames[] = {"gyro",        "accel",       "lidar",     "ground flat",
                                    "ground dist", "ground incl", "ground up", "other"};
  return kNames[group];
}

}  // namespace tiltcal::calibrate
