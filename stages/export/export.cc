#include "stages/export/export.h"

#include <fmt/format.h>

#include "common/io/atomic_file.h"
#include "common/io/text_proto.h"
#include "stages/export/exported_calibration.h"
#include "stages/export/formats.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::exporter {

Status Run(const ExportPaths& paths, const ExportOptions& options, std::ostream* stdout_stream) {
  const ExportFormat* format = FindExportFormat(options.format);
  if (format == nullptr) {
    return Status::Error(fmt::format("unknown --format=\"{}\" (one of: {})", options.format,
                                     ExportFormatNames()));
  }
  proto::CalibrationResult calibration;
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.calibration, &calibration));
  ExportedCalibration exported;
  TILTCAL_RETURN_IF_ERROR(MakeExportedCalibration(calibration, paths.calibration,
                                                  options.imu_frame, options.lidar_frame,
                                                  &exported));
  if (calibration.verdict() == proto::CalibrationResult::SUSPECT && !options.allow_suspect) {
    const std::string first_reason =
        calibration.verdict_reasons().empty() ? "no reason given" : calibration.verdict_reasons(0);
    return Status::Error(fmt::format(
        "{}: verdict SUSPECT ({}); not exported without --allow_suspect", paths.calibration,
        first_reason));
  }
  const std::string text = format->write(exported);
  if (paths.out.empty()) {
    *stdout_stream << text;
    stdout_stream->flush();
    return stdout_stream->good() ? Status::Ok() : Status::Error("cannot write to stdout");
  }
  return WriteFileAtomically(paths.out, text);
}

}  // namespace tiltcal::exporter
