#include "stages/calibrate/report/residual_type.h"

#include "stages/calibrate/residuals/accel_cost_function.h"
#include "stages/calibrate/residuals/drifting_time_offset_cost_function.h"
#include "stages/calibrate/residuals/ground_cost_functions.h"
#include "stages/calibrate/residuals/gyro_cost_function.h"
#include "stages/calibrate/residuals/point_to_plane_cost_function.h"
#include "stages/calibrate/residuals/stacked_cost_function.h"

namespace tiltcal::calibrate {

ResidualType TypeOf(const ceres::CostFunction* f) {
  if (const auto* stacked = dynamic_cast<const StackedCostFunction*>(f)) {
    return TypeOf(&stacked->row(0));
  }
  if (const auto* drifting = dynamic_cast<const DriftingTimeOffsetCostFunction*>(f)) {
    return TypeOf(&drifting->inner());
  }
  if (dynamic_cast<const GyroCostFunction*>(f) != nullptr) return kGyro;
  if (dynamic_cast<const AccelCostFunction*>(f) != nullptr) return kAccel;
  if (dynamic_cast<const PointToPlaneCostFunction*>(f) != nullptr) return kLidar;
  if (dynamic_cast<const FlatGroundCostFunction*>(f) != nullptr ||
      dynamic_cast<const DistanceCostFunction*>(f) != nullptr ||
      dynamic_cast<const InclinationCostFunction*>(f) != nullptr ||
      dynamic_cast<const UpCostFunction*>(f) != nullptr) {
    return kGround;
  }
  return kOther;
}

const char* ResidualTypeName(ResidualType type) {
  constexpr const char* kNames[] = {"gyro", "accel", "lidar", "ground", "other"};
  return kNames[type];
}

}  // namespace tiltcal::calibrate
