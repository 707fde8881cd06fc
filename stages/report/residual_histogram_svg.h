#ifndef TILTCAL_STAGES_REPORT_RESIDUAL_HISTOGRAM_SVG_H_
#define TILTCAL_STAGES_REPORT_RESIDUAL_HISTOGRAM_SVG_H_

#include <string>

#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::report {

// An inline SVG of one residual type's histogram (ResidualStatistics
// histogram_*, normalised residuals r / sigma) as bars of relative frequency
// density (count / (N w)), against the standard normal density
// exp(-r^2/2) / sqrt(2 pi) drawn as a curve, with the ±3 marks; the title
// gives the type, N, RMS and the counts outside the range. An entry without
// a histogram (a file written before it existed) gives a short note instead.
std::string ResidualHistogramSvg(const proto::ResidualStatistics& statistics);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_RESIDUAL_HISTOGRAM_SVG_H_
