#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_STATISTICS_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_STATISTICS_H_

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
// Over time (ResidualTimeSeriesParams): every residual block on a spline
// segment s (first parameter block rotation knot s) is dated at the middle
// of that segment, t0 + (s + 1/2) dt; the grid's span is cut in `bins` equal
// bins and each bin summarised (count, RMS, 5/50/95 % quantiles). The
// ground's distance and up residuals have no knot and no time.

#include <vector>

#include <ceres/problem.h>

#include "stages/calibrate/problem/calibration_state.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// One entry per type that has residuals, in the order gyro, accel, lidar, ground.
// `state` is the one whose blocks the problem holds (to date the residuals).
std::vector<proto::ResidualStatistics> ComputeResidualStatistics(
    ceres::Problem* problem, const CalibrationState& state,
    const proto::ResidualTimeSeriesParams& params);

// One scalar normalised residual and its time (s, IMU clock).
struct TimedResidual {
  double time_s = 0.0;
  double value = 0.0;
};

// Summary of the scalar values of one type (exposed for tests).
proto::ResidualStatistics SummariseResiduals(const char* type, std::vector<double> values);

// The time_* fields of `s`: [start_s, end_s) in `bins` equal bins (values
// outside are clamped into the first or last bin); quantiles by nearest rank
// (the value of rank ceil(q n) of the sorted bin).
void FillTimeSeries(const std::vector<TimedResidual>& values, double start_s, double end_s,
                    int bins, proto::ResidualStatistics* s);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_RESIDUAL_STATISTICS_H_
