#ifndef TILTCAL_STAGES_REPORT_REPORT_PAGE_H_
#define TILTCAL_STAGES_REPORT_REPORT_PAGE_H_

#include <string>
#include <vector>

#include "stages/report/map_snapshots.h"
#include "stages/report/page_exports.h"
#include "stages/report/report.h"
#include "stages/report/verify_section.h"
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
  // The wall drawn from both maps (note "maps not written" when absent).
  WallSnapshots snapshots;
  // The exports of its calibration (none for a SUSPECT one: exports_note).
  std::vector<PageExport> exports;
  std::string exports_note;
};

// The dataset's joint calibration (tiltcal_dataset_calibration's
// out/calibration.txtpb) and its exports.
struct DatasetPage {
  proto::CalibrationResult calibration;
  std::string calibration_link;
  std::vector<PageExport> exports;
  std::string exports_note;
};

// The dataset's report page: one self-contained HTML file (inline CSS and
// SVG, PNG as data: URIs; no script, no network): the dataset's calibration
// with σ, its per-sequence consistency and its exports (when `dataset` is
// given), the check against a stored calibration (when `verify` is given,
// verify_section.h), the repeatability table and, per sequence, the verdict and its
// reasons, the extrinsic and τ with σ, the map sharpness with the rig's
// extrinsic and with the estimate and the wall snapshots of both maps, the
// normalised residuals as histograms against N(0,1) and over time, the
// exports, and the links to the calibration and the map PCDs.
std::string FormatHtml(const std::string& title, const Repeatability& repeatability,
                       const std::vector<SequencePage>& sequences,
                       const DatasetPage* dataset = nullptr,
                       const VerifyPage* verify = nullptr);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_REPORT_PAGE_H_
