#ifndef TILTCAL_STAGES_REPORT_REPORT_PAGE_H_
#define TILTCAL_STAGES_REPORT_REPORT_PAGE_H_

#include <string>
#include <vector>

#include "stages/report/report.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::report {

// One sequence on the page: its calibration (calibration.txtpb, or the
// calibration.suspect.txtpb the pipeline set aside) and the files beside it
// as links relative to the page ("" when the file is absent).
struct SequencePage {
  std::string name;
  proto::CalibrationResult calibration;
  bool set_aside = false;  // SUSPECT: not in the repeatability rows
  std::string calibration_link;
  std::string map_rig_link;         // map_rig.pcd
  std::string map_calibrated_link;  // map_calibrated.pcd
};

// The dataset's report page: one self-contained HTML file (inline CSS and
// SVG, no script, no network) with the repeatability table and, per
// sequence, the verdict and its reasons, the extrinsic and τ with σ, the map
// sharpness with the rig's extrinsic and with the estimate, the normalised
// residual histograms against N(0,1), and the map PCDs and export commands.
std::string FormatHtml(const std::string& title, const Repeatability& repeatability,
                       const std::vector<SequencePage>& sequences);

// Text with & < > " escaped for HTML.
std::string EscapeHtml(const std::string& text);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_REPORT_PAGE_H_
