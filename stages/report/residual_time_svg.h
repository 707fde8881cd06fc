#ifndef TILTCAL_STAGES_REPORT_RESIDUAL_TIME_SVG_H_
#define TILTCAL_STAGES_REPORT_RESIDUAL_TIME_SVG_H_

#include <string>

#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::report {

// An inline SVG of one residual type over the sequence's time
// (ResidualStatistics time_*: normalised residuals r / sigma per time bin):
// the 5-95 % band, the median and the RMS of each non-empty bin at the
// bin's middle (empty bins break the lines), against the noise model's ±3
// (dashed) and 0; values clipped to ±5. An entry without the time bins (a
// file written before they existed) gives a short note instead.
std::string ResidualTimeSvg(const proto::ResidualStatistics& statistics);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_RESIDUAL_TIME_SVG_H_
