#ifndef TILTCAL_STAGES_INSPECT_GROUND_SUMMARY_H_
#define TILTCAL_STAGES_INSPECT_GROUND_SUMMARY_H_

#include <ostream>
#include <string>

#include "common/status.h"

namespace tiltcal::inspect {

// When `path` is a ground.binpb (GroundPlane stream), writes one line to
// `out`: scans, valid, and the rejected scans by reason, e.g.
//   "ground.binpb: 599 scans, 590 valid; rejected: poor_coverage=7 high_rms=2"
// Other files: nothing. Used by `tiltcal_inspect csv` (on stderr, so the
// table on stdout stays plot-ready).
Status PrintGroundSummary(const std::string& path, std::ostream& out);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_GROUND_SUMMARY_H_
