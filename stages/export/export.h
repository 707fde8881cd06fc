#ifndef TILTCAL_STAGES_EXPORT_EXPORT_H_
#define TILTCAL_STAGES_EXPORT_EXPORT_H_

#include <ostream>
#include <string>

#include "common/status.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::exporter {

struct ExportPaths {
  std::string calibration;  // a calibration.txtpb (or calibration.suspect.txtpb)
  std::string out;          // the exported text; "" writes it to `stdout`
};

struct ExportOptions {
  std::string format;  // a name of ExportFormats()
  // Export a SUSPECT calibration (its verdict and reasons go into the
  // comments of the output) instead of refusing it.
  bool allow_suspect = false;
  std::string imu_frame = "imu_link";
  std::string lidar_frame = "lidar_link";
};

// The text of `calibration` in `options.format` (what Run writes), with
// `source` (the file's name as given) in its header; refuses a SUSPECT
// calibration unless allowed. Used by tiltcal_report for the page's exports.
Status ExportText(const proto::CalibrationResult& calibration, const std::string& source,
                  const ExportOptions& options, std::string* text);

// Reads the calibration, refuses a SUSPECT one unless allowed, and writes
// the extrinsic and τ in `options.format` to paths.out (atomically) or to
// `stdout`. Every error names the file and what is wrong; no output is left
// behind on error.
Status Run(const ExportPaths& paths, const ExportOptions& options, std::ostream* stdout_stream);

}  // namespace tiltcal::exporter

#endif  // TILTCAL_STAGES_EXPORT_EXPORT_H_
