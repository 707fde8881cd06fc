#ifndef TILTCAL_STAGES_REPORT_PAGE_EXPORTS_H_
#define TILTCAL_STAGES_REPORT_PAGE_EXPORTS_H_

#include <string>
#include <vector>

#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::report {

// One export on the page: the tiltcal_export format name and its text.
struct PageExport {
  std::string format;
  std::string text;
};

// The formats the page shows, in order: fast_lio, lio_sam, urdf, tf_ros1,
// tf_ros2, kalibr.
const std::vector<std::string>& PageExportFormats();

// The texts tiltcal_export --calibration=<source> --format=<name> writes
// for `calibration` (exporter::ExportText, default frame names). A SUSPECT
// calibration is not exported: empty, with the reason in *note.
std::vector<PageExport> MakePageExports(const proto::CalibrationResult& calibration,
                                        const std::string& source, std::string* note);

}  // namespace tiltcal::report

#endif  // TILTCAL_STAGES_REPORT_PAGE_EXPORTS_H_
