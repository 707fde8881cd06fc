#ifndef TILTCAL_STAGES_CALIBRATE_REPORT_VERDICT_H_
#define TILTCAL_STAGES_CALIBRATE_REPORT_VERDICT_H_

// The verdict on a calibration (docs/design.md §11): a pure function of the
// filled CalibrationResult (estimate, observability, solver report, residual
// statistics, map sharpness, rig comparison, hand-eye, static start, tau
// bounds) and VerdictParams.
//
// SUSPECT rules (each adds one reason line):
//   - tau within at_bound_tolerance_s of a bound of the final solve
//     ([time_offset_lower_bound_s, time_offset_upper_bound_s]);
//   - the covariance could not be computed;
//   - the last solve did not converge (require_convergence);
//   - a residual type's normalised RMS above max_<type>_rms;
//   - the estimate's map thicker than max_map_thickness_ratio x the rig's;
//   - a large move from the rig (large_rotation_deg, large_translation_m)
//     whose map is not thinner than large_move_max_thickness_ratio x the
//     rig's (the data do not support the move);
//   - hand-eye C_bl and the final C_bl more than
//     max_hand_eye_disagreement_deg apart;
//   - no static start, or fewer than min_static_samples averaged
//     (require_static_start);
//   - the IMU intrinsics' score test found them but they were not
//     estimated (imu_intrinsics.found and not estimated: mode OFF).
// WEAK: no SUSPECT rule fired and the observability report marks directions
// weak; each is named with the value the rig (prior) gives it.
// OK otherwise. SUSPECT reasons come first, then the WEAK ones.

#include <string>

#include "tiltcal/proto/calibrate_params.pb.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::calibrate {

// Sets result->verdict() and result->verdict_reasons() (cleared first).
void DecideVerdict(const proto::VerdictParams& params, proto::CalibrationResult* result);

// The estimate moved more than large_rotation_deg or large_translation_m
// from the rig.
bool MovedFarFromRig(const proto::CalibrationResult& result, const proto::VerdictParams& params);

// The rig's and the estimate's extrinsic side by side, with the move
// (rotation_from_rig_deg, translation_from_rig_m): one line.
std::string DescribeMoveFromRig(const proto::CalibrationResult& result);

// "verdict WEAK" and one indented line per reason, then, when the estimate
// moved far from the rig, DescribeMoveFromRig: for the end of a run on stderr.
std::string FormatVerdict(const proto::CalibrationResult& result,
                          const proto::VerdictParams& params);

}  // namespace tiltcal::calibrate

#endif  // TILTCAL_STAGES_CALIBRATE_REPORT_VERDICT_H_
