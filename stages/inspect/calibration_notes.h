#ifndef TILTCAL_STAGES_INSPECT_CALIBRATION_NOTES_H_
#define TILTCAL_STAGES_INSPECT_CALIBRATION_NOTES_H_

#include "stages/inspect/check_findings.h"
#include "tiltcal/proto/check_params.pb.h"

namespace tiltcal::inspect {

// What the measured numbers mean for the calibration, in words: appends to
// f->notes (the calibration runs, with this consequence) and f->problems (it
// cannot run: no rotation at all).
void AddCalibrationNotes(const proto::CheckParams& params, CheckFindings* f);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_CALIBRATION_NOTES_H_
