#ifndef TILTCAL_STAGES_CALIBRATE_CALIBRATION_RESULT_H_
#define TILTCAL_STAGES_CALIBRATE_CALIBRATION_RESULT_H_

// The CalibrationResult of a finished solve besides the outer loop's own
// report (outer_loop.h): covariance and observability, the clock drift, the
// facts the verdict is decided from, the estimate, the initialisation's
// findings and the notes (docs/design.md §11).

#include <ostream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "stages/calibrate/calibrate.h"
#include "stages/calibrate/init/initialisation.h"
#include "stages/calibrate/outer_loop.h"
#include "stages/calibrate/problem/calibration_state.h"
#include "stages/calibrate/problem/time_offset_drift.h"
#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// The clock drift's setup (time_offset_drift.h): the scans' span (t_ref its
// middle) and whether rho is estimated, with its prior.
struct ClockDriftSetup {
  ScanTimeSpan span;
  TimeOffsetDriftDecision decision;
};

// What the report of a finished solve reads: the inputs, the params, the
// initialisation's report, the drift's setup, the outer loop (its last
// problem, and the default sample's: ReportProblem) and the final state.
struct SolvedCalibration {
  const CalibrateInputs& inputs;
  const proto::CalibrateParams& params;
  const InitialisationReport& init;
  const ClockDriftSetup& drift;
  const OuterLoop& loop;
  CalibrationState* state;
};

// What FillCovariance gives besides the result's fields:
// intrinsics_covariance: that of the IMU intrinsics when they are estimated
// (covariance_report.h), else empty;
// clock_rate_row: rho's row of the covariance (covariance_report.h), scaled
// as the 7x7 (rho's prior, ClockDriftSetup, kept like the translation's),
// when the drift is estimated; else empty.
struct CovarianceExtras {
  Eigen::MatrixXd intrinsics_covariance;
  std::vector<double> clock_rate_row;
};

// Covariance and observability on the last problem (the extrinsic and tau do
// not depend on the world gauge). The information is the last problem's,
// the variance factor the default sample's (ReportProblem).
void FillCovariance(const SolvedCalibration& solved, proto::CalibrationResult* result,
                    CovarianceExtras* extras);

// The clock drift's report (time_offset_drift.h) from the last problem and
// the covariance's rho row, its observability entry, and, when rho was
// estimated, its verdict note (also on stderr).
void FillTimeOffsetDrift(const SolvedCalibration& solved,
                         const std::vector<double>& clock_rate_row,
                         proto::CalibrationResult* result, std::ostream* log);

// The map sharpness with the estimate and with the rig's extrinsic.
struct MapSharpnessPair {
  proto::MapSharpness estimate;
  proto::MapSharpness rig;
  double seconds = 0.0;  // of both measurements, on whichever thread ran them
};
MapSharpnessPair MeasureBothMapSharpnesses(const CalibrateInputs& inputs,
                                           const proto::CalibrateParams& params,
                                           const CalibrationState& state);

// What the verdict is decided from besides the estimate and the covariance:
// residual statistics and tau bounds of the default sample's problem, the
// map sharpness with the estimate and with the rig's extrinsic (same
// trajectory and tau, measured by MeasureBothMapSharpnesses), the move from
// the rig, hand-eye and static start, the starting extrinsic's notes.
void FillVerdictFacts(const SolvedCalibration& solved, MapSharpnessPair sharpness,
                      proto::CalibrationResult* result);

// The estimated IMU intrinsics as a verdict note (and on stderr): values,
// sigmas and what the motion left at the prior.
void AddImuIntrinsicsNote(proto::CalibrationResult* result, std::ostream* log);

// The estimate (state already in the gauge C_ab(t0) = 1, r_a^{ba}(t0) = 0)
// and the ground residuals used.
void FillEstimate(const CalibrationState& state, const std::vector<std::string>& ground_used,
                  const std::string& ground_reason, proto::CalibrationResult* result);

// The initialisation's findings for the verdict (CalibrationResult 80-89)
// and its odometry's counts and registration quality (111-115).
void FillInitialisationFacts(const InitialisationReport& init, proto::CalibrationResult* result);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_CALIBRATION_RESULT_H_
