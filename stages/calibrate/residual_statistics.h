#ifndef TILTCAL_STAGES_CALIBRATE_RESIDUAL_STATISTICS_H_
#define TILTCAL_STAGES_CALIBRATE_RESIDUAL_STATISTICS_H_

// Normalised residuals per type at the current parameter values of a
// calibration problem: every residual block is evaluated without its robust
// loss (the cost functions already divide by their sigma), and the scalar
// components are summarised per type (ResidualStatistics: count, RMS, median
// |r|, and a histogram of r over [-5, 5) in bins of 0.25). With the noise
// model right, RMS ~ 1 and median |r| ~ 0.674.
// Types by cost function: "gyro" (GyroCostFunction), "accel"
// (AccelCostFunction), "lidar" (PointToPlaneCostFunction), "ground" (the
// four ground residuals of ground_cost_functions.h). Priors and bias random
// walks are left out.

#include <vector>

#include <ceres/problem.h>

#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// One entry per type that has residuals, in the order gyro, accel, lidar, ground.
std::vector<proto::ResidualStatistics> ComputeResidualStatistics(ceres::Problem* problem);

// Summary of the scalar values of one type (exposed for tests).
proto::ResidualStatistics SummariseResiduals(const char* type, std::vector<double> values);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_RESIDUAL_STATISTICS_H_
