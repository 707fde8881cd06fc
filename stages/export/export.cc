#include "stages/export/export.h"

#include <fmt/format.h>

#include "common/io/atomic_file.h"
#include "common/io/text_proto.h"
#include "stages/export/exported_calibration.h"
#include "stages/export/formats.h"
#include "tiltcal/proto/calibration.pb.h"

namespace tiltcal::exporter {

Status ExportText(const proto::CalibrationResult& calibration, const std::string& source,
                  const ExportOptions& options, std::string* text) {
  const ExportFormat* format = FindExportFormat(options.format);
  if (format == nullptr) {
    return Status::Error(fmt::format("unknown --format=\"{}\" (one of: {})", options.format,
                                     ExportFormatNames()));
  }
  ExportedCalibration exported;
  TILTCAL_RETURN_IF_ERROR(MakeExportedCalibration(calibration, source, options.imu_frame,
                                                  options.lidar_frame, &exported));
  if (calibration.verdict() == proto::CalibrationResult::SUSPECT && !options.allow_suspect) {
    const std::string first_reason =
        calibration.verdict_reasons().empty() ? "no reason given" : calibration.verdict_reasons(0);
    return Status::Error(fmt::format("{}: verdict SUSPECT ({}); not exported without "
                                     "--allow_suspect",
                                     source, first_reason));
  }
  *text = format->write(exported);
  return Status::Ok();
}

Status Run(const ExportPaths& paths, const ExportOptions& options, std::ostream* stdout_stream) {
  if (FindExportFormat(options.format) == nullptr) {
    return Status::Error(fmt::format("unknown --format=\"{}\" (one of: {})", options.format,
                                     ExportFormatNames()));
  }
  proto::CalibrationResult calibration;
  TILTCAL_RETURN_IF_ERROR(ReadTextProto(paths.calibration, &calibration));
  std::string text;
  TILTCAL_RETURN_IF_ERROR(ExportText(calibration, paths.calibration, options, &text));
  if (paths.out.empty()) {
    *stdout_stream << text;
    stdout_stream->flush();
    return stdout_stream->good() ? Status::Ok() : Status::Error("cannot write to stdout");
  }
  return WriteFileAtomically(paths.out, text);
}

}  // namespace tiltcal::exporter
