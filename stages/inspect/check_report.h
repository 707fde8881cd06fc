#ifndef TILTCAL_STAGES_INSPECT_CHECK_REPORT_H_
#define TILTCAL_STAGES_INSPECT_CHECK_REPORT_H_

#include <ostream>

#include "stages/inspect/check_findings.h"

namespace tiltcal::inspect {

// The findings as aligned text: sections bag, IMU, LiDAR, clock, excitation,
// then "for the calibration" (the notes) and a last line
// "verdict: can be calibrated" or "verdict: cannot be calibrated" followed by
// the problems, one per line.
void WriteCheckReport(const CheckFindings& findings, std::ostream& out);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_CHECK_REPORT_H_
