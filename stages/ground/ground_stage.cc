#include "stages/ground/ground_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>

#include "common/imu/gyro_integrator.h"
#include "common/imu/imu_reading.h"
#include "common/imu/static_detection.h"
#include "common/io/atomic_file.h"
#include "common/io/eigen_proto.h"
#include "common/io/imu_stream.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/rig.h"
#include "common/io/static_detection_params.h"
#include "stages/ground/deskew.h"
#include "stages/ground/ground_params.h"
#include "stages/ground/scan_plane.h"
#include "stages/ground/scan_processor.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal::ground {

namespace {

using Clock = std::chrono::steady_clock;

// Counts and timings of a run.
struct RunSummary {
  int num_scans = 0;
  int num_valid = 0;
  int num_deskewed = 0;
  std::map<proto::GroundRejectReason, int> rejected;  // by reason
  bool static_start = false;
  double static_duration_s = 0.0;
  double deskew_s = 0.0, segment_s = 0.0, fit_s = 0.0, total_s = 0.0;
};

// C_ab(t) for deskewing: the gyro integrated from the first IMU stamp with
// the bias of the static start (zero without one). Empty (the IMU file not
// read) when deskewing is off.
struct ImuAttitude {
  int64_t origin_ns = 0;
  imu::StaticInterval static_start;
  imu::GyroIntegrator integrator;
};

Status ReadImuAttitude(const std::string& path, const proto::GroundDeskewParams& params,
                       ImuAttitude* attitude) {
  std::vector<imu::ImuReading> readings;
  if (params.enabled()) {
    TILTCAL_RETURN_IF_ERROR(ReadImuReadings(path, &readings, &attitude->origin_ns));
  }
  if (!readings.empty()) {
    attitude->static_start =
        imu::DetectStaticStart(readings, ToStaticDetectionOptions(params.static_detection()));
  }
  attitude->integrator = imu::GyroIntegrator(
      readings, attitude->static_start.found ? attitude->static_start.mean_gyro_radps
                                             : Eigen::Vector3d::Zero());
  return Status::Ok();
}

Status CheckScan(const std::string& path, int64_t record, const proto::Scan& scan) {
  const int n = scan.x_size();
  const std::string where = path + ": record " + std::to_string(record) + ": ";
  if (scan.y_size() != n || scan.z_size() != n) {
    return Status::Error(where + "point columns x, y, z have different lengths");
  }
  if (scan.intensity_size() != 0 && scan.intensity_size() != n) {
    return Status::Error(where + "intensity column length differs from x");
  }
  if (scan.ring_size() != 0 && scan.ring_size() != n) {
    return Status::Error(where + "ring column length differs from x");
  }
  if (scan.time_offset_ns_size() != 0 && scan.time_offset_ns_size() != n) {
    return Status::Error(where + "time_offset_ns column length differs from x");
  }
  return Status::Ok();
}

// Processes every scan of `reader` (paths.scans) into `planes`, in stream
// order; writes the deskewed scans to `scan_writer` when it is not null.
Status ProcessScans(const std::string& scans_path, RecordReader* reader,
                    ScanProcessor* processor, RecordWriter* scan_writer, std::ostream* log,
                    std::vector<proto::GroundPlane>* planes, RunSummary* summary) {
  // Progress on stderr only when it is a terminal.
  const bool progress = log != nullptr && ::isatty(STDERR_FILENO) != 0;
  proto::Scan scan;
  for (int64_t record = 0;; ++record) {
    bool end = false;
    scan.Clear();
    TILTCAL_RETURN_IF_ERROR(reader->Read(&scan, &end));
    if (end) break;
    TILTCAL_RETURN_IF_ERROR(CheckScan(scans_path, record, scan));
    planes->push_back(processor->Process(&scan));
    summary->deskew_s += processor->last_deskew_s();
    summary->segment_s += processor->last_segment_s();
    summary->fit_s += processor->last_fit_s();
    if (planes->back().deskewed()) ++summary->num_deskewed;
    if (scan_writer != nullptr) TILTCAL_RETURN_IF_ERROR(scan_writer->Write(scan));
    if (progress && (record + 1) % 50 == 0) {
      *log << "\rtiltcal_ground: " << (record + 1) << " scans" << std::flush;
    }
  }
  if (progress) *log << "\r";
  return Status::Ok();
}

Status WriteGroundPlanes(const std::vector<proto::GroundPlane>& planes, RecordWriter* writer,
                         RunSummary* summary) {
  for (const proto::GroundPlane& plane : planes) {
    TILTCAL_RETURN_IF_ERROR(writer->Write(plane));
    ++summary->num_scans;
    if (plane.valid()) {
      ++summary->num_valid;
    } else {
      ++summary->rejected[plane.reject_reason()];
    }
  }
  return Status::Ok();
}

void LogSummary(const RunSummary& summary, std::ostream* log) {
  if (log == nullptr) return;
  const double per_scan = summary.num_scans > 0 ? 1e3 / summary.num_scans : 0.0;
  *log << fmt::format(
      "tiltcal_ground: {} scans, {} valid, {} deskewed; gyro bias from static start: {} "
      "({:.2f} s); per scan: deskew {:.2f} ms, segment {:.2f} ms, fit {:.2f} ms; "
      "total {:.2f} s\n",
      summary.num_scans, summary.num_valid, summary.num_deskewed,
      summary.static_start ? "yes" : "no", summary.static_duration_s,
      summary.deskew_s * per_scan, summary.segment_s * per_scan, summary.fit_s * per_scan,
      summary.total_s);
  if (!summary.rejected.empty()) {
    *log << "tiltcal_ground: rejected:";
    for (const auto& [reason, count] : summary.rejected) {
      *log << " " << ReasonName(reason) << "=" << count;
    }
    *log << "\n";
  }
}

}  // namespace

std::string ReasonName(proto::GroundRejectReason reason) {
  std::string name = proto::GroundRejectReason_Name(reason);
  if (name.rfind("GROUND_", 0) == 0) name = name.substr(7);
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name;
}

Status Run(const GroundPaths& paths, const proto::GroundParams& params, std::ostream* log) {
  const auto start = Clock::now();
  TILTCAL_RETURN_IF_ERROR(ValidateGroundParams(params).WithContext("params"));
  if (paths.scans.empty() || paths.rig.empty() || paths.out_ground.empty() ||
      paths.imu.empty()) {
    return Status::Error("--imu, --scans, --rig and --out_ground are required");
  }
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_ground));
  if (!paths.out_scans.empty()) TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_scans));
  proto::Rig rig;
  TILTCAL_RETURN_IF_ERROR(LoadRigWithExtrinsic(paths.rig, &rig));
  ImuAttitude attitude;
  TILTCAL_RETURN_IF_ERROR(ReadImuAttitude(paths.imu, params.deskew(), &attitude));
  RunSummary summary;
  summary.static_start = attitude.static_start.found;
  summary.static_duration_s =
      attitude.static_start.found ? attitude.static_start.end_s - attitude.static_start.begin_s
                                  : 0.0;
  Deskewer deskewer(&attitude.integrator, attitude.origin_ns,
                    ToEigen(rig.imu_from_lidar().rotation()).toRotationMatrix(), params.deskew());
  ScanProcessor processor(params, MakeGroundFrame(rig, params.frame()), &deskewer);

  RecordReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(paths.scans, proto::Scan::descriptor()->full_name()));
  std::vector<InputPath> inputs = {{"imu", paths.imu}, {"scans", paths.scans}, {"rig", paths.rig}};
  if (!paths.params.empty()) inputs.push_back({"params", paths.params});
  const proto::Provenance provenance =
      MakeProvenance("tiltcal_ground", params, inputs, paths.command_line);
  std::unique_ptr<RecordWriter> scan_writer;
  if (!paths.out_scans.empty()) {
    scan_writer = std::make_unique<RecordWriter>();
    TILTCAL_RETURN_IF_ERROR(scan_writer->Open(paths.out_scans,
                                              proto::Scan::descriptor()->full_name(), provenance,
                                              /*compress=*/true));
  }
  std::vector<proto::GroundPlane> planes;
  TILTCAL_RETURN_IF_ERROR(ProcessScans(paths.scans, &reader, &processor, scan_writer.get(), log,
                                       &planes, &summary));
  ApplyTiltJumpGate(params.tilt_jump_gate(), &planes);

  // The deskewed scans are renamed into place only once the planes are written.
  RecordWriter writer;
  TILTCAL_RETURN_IF_ERROR(writer.Open(paths.out_ground,
                                      proto::GroundPlane::descriptor()->full_name(), provenance,
                                      /*compress=*/false));
  TILTCAL_RETURN_IF_ERROR(WriteGroundPlanes(planes, &writer, &summary));
  if (scan_writer) TILTCAL_RETURN_IF_ERROR(scan_writer->Close());
  TILTCAL_RETURN_IF_ERROR(writer.Close());
  summary.total_s = std::chrono::duration<double>(Clock::now() - start).count();
  LogSummary(summary, log);
  return Status::Ok();
}

}  // namespace tiltcal::ground
