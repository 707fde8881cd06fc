#include "stages/report/page_exports.h"

#include "stages/export/export.h"

namespace tiltcal::report {

const std::vector<std::string>& PageExportFormats() {
  static const std::vector<std::string> formats = {"fast_lio", "lio_sam", "urdf",
                                                   "tf_ros1",  "tf_ros2", "kalibr"};
  return formats;
}

std::vector<PageExport> MakePageExports(const proto::CalibrationResult& calibration,
                                        const std::string& source, std::string* note) {
  std::vector<PageExport> exports;
  note->clear();
  for (const std::string& format : PageExportFormats()) {
    exporter::ExportOptions options;
    options.format = format;
    PageExport e{format, ""};
    const Status status = exporter::ExportText(calibration, source, options, &e.text);
    if (!status.ok()) {
      *note = status.message();
      return {};
    }
    exports.push_back(std::move(e));
  }
  return exports;
}

}  // namespace tiltcal::report
