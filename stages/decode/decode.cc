#include "stages/decode/decode.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <vector>

#include <fmt/format.h>

#include "bag/input/bag_input.h"
#include "bag/input/static_transforms.h"
#include "bag/message_reader.h"
#include "common/checked_conversion.h"
#include "common/cli/command_line.h"
#include "common/io/atomic_file.h"
#include "common/io/directory_lock.h"
#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/rig.h"
#include "stages/decode/async_record_writer.h"
#include "stages/decode/clock_domains.h"
#include "stages/decode/decode_params.h"
#include "stages/decode/imu_units_resolution.h"
#include "stages/decode/livox_conversion.h"
#include "stages/decode/message_sinks.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {

namespace {

using Clock = std::chrono::steady_clock;

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out.empty() ? "(none)" : out;
}

// Chooses the topic of one of the message types `types`: the params'
// topic, else the rig's, else the only topic of those types in the bag.
// *type is the chosen topic's type.
Status ChooseTopic(const bag::MessageReader& reader, const std::vector<std::string>& types,
                   const std::string& params_topic, const std::string& rig_topic,
                   const char* params_field, std::string* topic, std::string* type) {
  std::vector<std::string> candidates;
  for (const std::string& t : types) {
    for (const std::string& name : reader.TopicsOfType(t)) candidates.push_back(name);
  }
  std::sort(candidates.begin(), candidates.end());
  std::string type_names;  // "sensor_msgs/PointCloud2 or livox_ros_driver/CustomMsg"
  for (const std::string& t : types) type_names += (type_names.empty() ? "" : " or ") + t;
  auto describe = [&](const std::vector<std::string>& topics) {
    std::vector<std::string> items;
    for (const std::string& t : topics) {
      items.push_back("'" + t + "' (" + std::to_string(reader.MessageCount(t)) + " msgs)");
    }
    return Join(items);
  };
  const std::string& requested = !params_topic.empty() ? params_topic : rig_topic;
  if (!requested.empty()) {
    const char* origin = !params_topic.empty() ? "params" : "rig";
    const std::string actual = reader.TopicType(requested);
    if (actual.empty()) {
      return Status::Error(reader.path() + ": no topic '" + requested + "' (" + params_field +
                           " from the " + origin + ") in the bag; " + type_names +
                           " topics: " + describe(candidates));
    }
    if (std::find(types.begin(), types.end(), actual) == types.end()) {
      return Status::Error(reader.path() + ": topic '" + requested + "' (" + params_field +
                           " from the " + origin + ") has type " + actual + ", expected " +
                           type_names);
    }
    *topic = requested;
    *type = actual;
    return Status::Ok();
  }
  if (candidates.empty()) {
    std::string others;  // "sensor_msgs/PointCloud2 topic (nor livox_ros_driver/CustomMsg)"
    for (size_t i = 1; i < types.size(); ++i) others += (i == 1 ? "" : ", ") + types[i];
    return Status::Error(reader.path() + ": no " + types[0] + " topic" +
                         (others.empty() ? "" : " (nor " + others + ")") +
                         " in the bag (topics: " + Join(reader.TopicNames()) + ")");
  }
  if (candidates.size() > 1) {
    return Status::Error(reader.path() + ": several " + type_names + " topics: " +
                         describe(candidates) + "; choose one with " + params_field +
                         " in the params or the rig");
  }
  *topic = candidates[0];
  *type = reader.TopicType(*topic);
  return Status::Ok();
}

double RateHz(int64_t count, int64_t first_ns, int64_t last_ns) {
  if (count < 2 || last_ns <= first_ns) return 0.0;
  return static_cast<double>(count - 1) / (static_cast<double>(last_ns - first_ns) * 1e-9);
}

// One topic's line of the summary: messages read and written, rate, stamp
// range and what was dropped.
std::string TopicLine(const char* label, const std::string& topic, int64_t messages,
                      int64_t written, int64_t first_ns, int64_t last_ns,
                      const std::string& dropped) {
  return fmt::format("  {} '{}': {} msgs, {} written, {:.2f} Hz, stamps {} .. {} s ({:.3f} s); "
                     "dropped {}\n",
                     label, topic, messages, written, RateHz(written, first_ns, last_ns),
                     FormatSeconds(first_ns), FormatSeconds(last_ns),
                     static_cast<double>(last_ns - first_ns) * 1e-9, dropped);
}

void PrintSummary(std::ostream* log, const DecodePaths& paths,
                  const proto::DecodeParams& params, const DecodeSummary& s) {
  const double shift_s = params.lidar_stamp_shift_s();
  if (log == nullptr) return;
  const double mb = static_cast<double>(s.bag_bytes) * 1e-6;
  *log << fmt::format("tiltcal_decode: {}: {}, {:.1f} MB, {}\n", paths.bag, s.bag_format, mb,
                      s.indexed ? "indexed" : "UNINDEXED (linear scan)");
  if (s.bag_files.size() > 1) {
    *log << fmt::format("  merged in record time: {}; {} duplicate messages dropped (the same "
                        "topic, record time and bytes in an earlier file)\n",
                        Join(s.bag_files), s.duplicates_dropped);
  }
  if (s.salvaged_messages > 0 || !s.salvage_note.empty()) {
    *log << fmt::format("  salvaged {} messages from the unindexed bag{}{}\n",
                        s.salvaged_messages, s.salvage_note.empty() ? "" : "; ",
                        s.salvage_note);
  }
  for (const std::string& warning : s.bag_warnings) *log << "  WARNING: bag: " << warning << "\n";
  *log << TopicLine("imu  ", s.imu_topic, s.imu_messages, s.imu_written, s.imu_first_stamp_ns,
                    s.imu_last_stamp_ns,
                    fmt::format("{} duplicate + {} conflicting stamps", s.imu_duplicates_dropped,
                                s.imu_conflicting_dropped));
  *log << TopicLine("lidar", s.lidar_topic, s.scan_messages, s.scans_written,
                    s.scan_first_stamp_ns, s.scan_last_stamp_ns,
                    fmt::format("{} non-monotonic + {} empty scans",
                                s.scans_non_monotonic_dropped, s.scans_empty_dropped));
  *log << fmt::format("  points: {} written; dropped {} NaN/Inf, {} zero/short range{}\n",
                      s.points_written, s.points_dropped_invalid, s.points_dropped_range,
                      !IsLivoxCustomMsgType(s.lidar_type)
                          ? ""
                          : fmt::format(", {} tagged as noise (Livox tag & {:#04x})",
                                        s.points_dropped_noise_tag,
                                        params.livox().noise_tag_mask()));
  *log << fmt::format("  clocks: IMU and LiDAR stamps overlap for {:.3f} s{}\n", s.stamp_overlap_s,
                      shift_s != 0.0
                          ? fmt::format(" (LiDAR stamps shifted by {:.3f} s, lidar_stamp_shift_s)",
                                        shift_s)
                          : "");
  if (s.lidar_clock_vs_imu.measured && s.clock_drift_note.empty()) {
    *log << fmt::format("  clocks: the LiDAR clock runs {:+.1f} ± {:.1f} ppm against the IMU's\n",
                        s.lidar_clock_vs_imu.rate_ppm, s.lidar_clock_vs_imu.sigma_ppm);
  }
  if (!s.clock_drift_note.empty()) *log << "  WARNING: clocks: " << s.clock_drift_note << "\n";
  *log << "  tf_static: " << s.tf_static.summary << "\n";
  for (const std::string& warning : s.tf_static.warnings) {
    *log << "  WARNING: tf_static: " << warning << "\n";
  }
  for (const std::string& note : s.imu_notes) {
    const bool warning =
        std::find(s.imu_warnings.begin(), s.imu_warnings.end(), note) != s.imu_warnings.end();
    *log << (warning ? "  WARNING: imu: " : "  imu: ") << note << "\n";
  }
  if (s.scans_without_point_time > 0) {
    *log << fmt::format(
        "  WARNING: {} scans have no per-point time field (time_source POINT_TIME_NONE): "
        "they cannot be deskewed\n",
        s.scans_without_point_time);
  }
  *log << fmt::format("  wall {:.3f} s, {:.1f} MB/s, {} chunks decompressed\n", s.wall_s,
                      s.wall_s > 0 ? mb / s.wall_s : 0.0, s.chunks_decompressed);
}

// "tiltcal_decode:  42% (…)" rewritten in place at most every 250 ms, only
// on a terminal.
class ProgressLine {
 public:
  ProgressLine(std::ostream* log, int64_t total)
      : log_(cli::IsTerminalLog(log) ? log : nullptr), total_(total), last_(Clock::now()) {}
  ~ProgressLine() {
    if (log_ != nullptr) *log_ << "\r\033[K" << std::flush;
  }

  void Update(uint64_t sequence) {
    if (log_ == nullptr || (sequence & 255) != 0) return;
    const Clock::time_point now = Clock::now();
    if (now - last_ <= std::chrono::milliseconds(250)) return;
    last_ = now;
    *log_ << fmt::format("\rtiltcal_decode: {:3.0f}% ({} / {} messages)",
                         total_ > 0 ? 100.0 * static_cast<double>(sequence) / total_ : 0.0,
                         sequence, total_)
          << std::flush;
  }

 private:
  std::ostream* log_;
  int64_t total_;
  Clock::time_point last_;
};

Status CheckPaths(const DecodePaths& paths) {
  if (paths.bag.empty()) return Status::Error("no input bag (--bag)");
  if (paths.out_imu.empty()) return Status::Error("no IMU output path (--out_imu)");
  if (paths.out_scans.empty()) return Status::Error("no scan output path (--out_scans)");
  if (paths.out_imu == paths.out_scans) {
    return Status::Error("--out_imu and --out_scans name the same file " + paths.out_imu);
  }
  TILTCAL_RETURN_IF_ERROR(CheckOutputPath(paths.out_imu));
  return CheckOutputPath(paths.out_scans);
}

// Opens the bag and chooses its IMU and LiDAR topics (params, else rig, else
// the only topic of the type).
Status OpenBag(const DecodePaths& paths, const proto::DecodeParams& params, const proto::Rig& rig,
               std::unique_ptr<bag::MessageReader>* input, DecodeSummary* s) {
  bag::Ros1ChunkSettings ros1_chunks;
  ros1_chunks.cache_size = std::max<uint32_t>(params.chunk_cache_size(), 1);
  ros1_chunks.read_ahead = params.read_ahead_chunks();
  bag::ReaderLimits limits;
  if (params.max_decompressed_chunk_mib() > 0) {
    limits.max_chunk_bytes = uint64_t{params.max_decompressed_chunk_mib()} << 20;
  }
  TILTCAL_RETURN_IF_ERROR(bag::OpenBagInput(paths.bag, ros1_chunks, input, limits));
  const bag::MessageReader* reader = input->get();
  s->bag_bytes = reader->size_bytes();
  s->bag_format = reader->format_name();
  s->bag_files = reader->input_files();
  s->indexed = reader->indexed();
  s->salvaged_messages = reader->num_salvaged_messages();
  s->salvage_note = reader->salvage_note();
  s->bag_warnings = reader->warnings();
  // A topic missing because the reader left data out says so (one line).
  std::string left_out;
  for (const std::string& w : s->bag_warnings) left_out += "; " + w;
  auto with_left_out = [&](const Status& status) {
    if (status.ok() || left_out.empty()) return status;
    return Status::Error(status.message() + " (the reader left data out" + left_out + ")");
  };
  if (reader->TotalMessageCount() == 0) {
    return with_left_out(
        Status::Error(paths.bag + ": the bag holds no messages" +
                      (s->salvage_note.empty() ? "" : " (" + s->salvage_note + ")")));
  }
  const bag::SensorTypes types = bag::SensorTypesOf(*reader);
  std::string imu_type;
  TILTCAL_RETURN_IF_ERROR(with_left_out(ChooseTopic(*reader, {types.imu}, params.imu_topic(),
                                                    rig.imu_topic(), "imu_topic",
                                                    &s->imu_topic, &imu_type)));
  TILTCAL_RETURN_IF_ERROR(with_left_out(ChooseTopic(*reader, types.Lidar(), params.lidar_topic(),
                                                    rig.lidar_topic(), "lidar_topic",
                                                    &s->lidar_topic, &s->lidar_type)));
  if (s->imu_topic == s->lidar_topic) {
    return Status::Error(paths.bag + ": imu and lidar topic are the same: " + s->imu_topic);
  }
  return Status::Ok();
}

// The two topics inside the time window of the params, on record time,
// relative to the bag's first message.
Status MakeReadOptions(const bag::MessageReader& reader, const proto::DecodeParams& params,
                       const DecodeSummary& s, bag::MessageSelection* options) {
  options->topics = {s.imu_topic, s.lidar_topic};
  int64_t bag_start_ns = 0;
  int64_t bag_end_ns = 0;
  (void)reader.TimeRange(&bag_start_ns, &bag_end_ns);
  if (params.start_offset_s() <= 0 && params.duration_s() <= 0) return Status::Ok();
  // The schema bounds both fields to 10^7 s (10^16 ns); checked here too
  // for callers that bypass the params loader.
  const std::optional<int64_t> offset_ns = SecondsToNs(params.start_offset_s());
  const std::optional<int64_t> duration_ns = SecondsToNs(params.duration_s());
  const std::optional<int64_t> start_ns =
      offset_ns ? CheckedAdd(bag_start_ns, *offset_ns) : std::nullopt;
  const std::optional<int64_t> end_ns =
      start_ns && duration_ns ? CheckedAdd(*start_ns, *duration_ns) : std::nullopt;
  if (!end_ns) {
    return Status::Error(fmt::format("{}: start_offset_s {} and duration_s {} overflow the stamps",
                                     reader.path(), params.start_offset_s(), params.duration_s()));
  }
  options->start_ns = *start_ns;
  if (params.duration_s() > 0) options->end_ns = *end_ns;
  if (options->start_ns > bag_end_ns) {
    return Status::Error(reader.path() + ": start_offset_s " +
                         std::to_string(params.start_offset_s()) +
                         " is past the end of the bag (" +
                         std::to_string(static_cast<double>(bag_end_ns - bag_start_ns) * 1e-9) +
                         " s long)");
  }
  return Status::Ok();
}

Status CheckSomethingWritten(const std::string& bag, const ImuSink& imu, const DecodeSummary& s) {
  if (s.scans_written == 0) {
    return Status::Error(bag + ": no usable scan on topic '" + s.lidar_topic + "' (" +
                         std::to_string(s.scan_messages) + " messages in the window, " +
                         std::to_string(s.scans_empty_dropped) + " without valid points)");
  }
  if (imu.empty()) {
    return Status::Error(bag + ": no IMU message on topic '" + s.imu_topic +
                         "' in the time window");
  }
  return Status::Ok();
}

// The clocks (the LiDAR and IMU stamps overlap) and the IMU's units and
// sign, once every message is read and before anything is written.
Status CheckStampsAndUnits(const DecodePaths& paths, const proto::DecodeParams& params,
                           const proto::Rig& rig, const ImuSink& imu, const ScanSink& scans,
                           DecodeSummary* s) {
  const decode::StampSpan imu_span = imu.Span();
  const decode::StampSpan lidar_span = scans.Span(*s);
  TILTCAL_RETURN_IF_ERROR(decode::CheckClockDomains(paths.bag, imu_span, lidar_span,
                                                    params.lidar_stamp_shift_s()));
  s->stamp_overlap_s = decode::StampOverlapSeconds(imu_span, lidar_span);
  const bool given = params.has_clock_drift();
  const double window_s = given ? params.clock_drift().window_s() : 2.0;
  const double max_drift_s = given ? params.clock_drift().max_time_offset_drift_s() : 5e-4;
  s->lidar_clock_vs_imu = timing::ClockRateBetween(scans.ClockRate(window_s),
                                                   imu.ClockRate(window_s), s->stamp_overlap_s);
  s->clock_drift_note =
      timing::DescribeClockDrift(s->lidar_clock_vs_imu, s->stamp_overlap_s, max_drift_s);
  decode::ImuUnitsResolution units;
  TILTCAL_RETURN_IF_ERROR(decode::ResolveImuUnits(imu.Readings(), rig, {paths.bag, paths.rig},
                                                  params.imu_units(), &units));
  s->accel_to_si = units.accel_to_si;
  s->gyro_to_si = units.gyro_to_si;
  s->imu_notes = units.notes;
  s->imu_warnings = units.warnings;
  return Status::Ok();
}

// One run at a time writes into the outputs' folders (two decodes of the
// same outputs would race on the commit manifests); folders locked in name
// order, so that two runs never wait for each other.
Status LockOutputDirectories(const DecodePaths& paths, std::ostream* log,
                             DirectoryLock locks[2]) {
  std::set<std::string> out_dirs = {OutputDirectory(paths.out_imu),
                                    OutputDirectory(paths.out_scans)};
  int locked = 0;
  for (const std::string& dir : out_dirs) {
    TILTCAL_RETURN_IF_ERROR(locks[locked++].Acquire(dir, "tiltcal_decode", log));
  }
  return Status::Ok();
}

// The provenance of both outputs: the bag as named, and every file read when
// they differ from it; the rig; /tf_static; what the reader left out.
proto::Provenance OutputProvenance(const DecodePaths& paths, const proto::DecodeParams& params,
                                   const DecodeSummary& s) {
  std::vector<InputPath> input_paths = {{"bag", paths.bag}};
  if (s.bag_files != std::vector<std::string>{paths.bag}) {
    for (const std::string& file : s.bag_files) input_paths.push_back({"bag file", file});
  }
  if (!paths.rig.empty()) input_paths.push_back({"rig", paths.rig});
  proto::Provenance provenance =
      MakeProvenance("tiltcal_decode", params, input_paths, paths.command_line);
  *provenance.mutable_tf_static() = bag::ToProto(s.tf_static);
  if (!s.salvage_note.empty()) provenance.add_notes("bag salvaged: " + s.salvage_note);
  for (const std::string& warning : s.bag_warnings) provenance.add_notes("bag: " + warning);
  return provenance;
}

Status OpenScansWriter(const DecodePaths& paths, const proto::DecodeParams& params,
                       const proto::Provenance& provenance, AsyncRecordWriter* writer) {
  Lz4FrameOptions scans_frame;
  scans_frame.compress_blocks = !params.scans_output().store_blocks();
  scans_frame.content_checksum = !params.scans_output().omit_content_checksum();
  AtomicFileOptions scans_file;
  scans_file.bypass_page_cache = params.scans_output().bypass_page_cache();
  return writer->Open(paths.out_scans, proto::Scan::descriptor()->full_name(), provenance,
                      scans_frame, scans_file);
}

}  // namespace

Status Decode(const DecodePaths& paths, const proto::DecodeParams& params, std::ostream* log,
              DecodeSummary* summary) {
  const Clock::time_point t0 = Clock::now();
  DecodeSummary s;
  TILTCAL_RETURN_IF_ERROR(CheckPaths(paths));
  DirectoryLock locks[2];
  TILTCAL_RETURN_IF_ERROR(LockOutputDirectories(paths, log, locks));
  // A run killed while committing its pair: finish that commit first.
  TILTCAL_RETURN_IF_ERROR(CompleteInterruptedCommit(paths.out_imu));
  TILTCAL_RETURN_IF_ERROR(CompleteInterruptedCommit(paths.out_scans));
  TILTCAL_RETURN_IF_ERROR(decode::ValidateDecodeParams(params).WithContext(
      paths.params.empty() ? "decode params" : paths.params));
  proto::Rig rig;
  if (!paths.rig.empty()) TILTCAL_RETURN_IF_ERROR(LoadRig(paths.rig, &rig));
  std::unique_ptr<bag::MessageReader> input;
  TILTCAL_RETURN_IF_ERROR(OpenBag(paths, params, rig, &input, &s));
  bag::MessageReader& reader = *input;
  bag::MessageSelection options;
  TILTCAL_RETURN_IF_ERROR(MakeReadOptions(reader, params, s, &options));
  // The extrinsic of the vehicle's URDF, when /tf_static joins the sensors'
  // frames: before the outputs are opened, so that both provenances hold it.
  TILTCAL_RETURN_IF_ERROR(
      bag::ReadStaticTransforms(reader, s.imu_topic, s.lidar_topic, &s.tf_static));

  const proto::Provenance provenance = OutputProvenance(paths, params, s);
  // Scans are serialized, framed and written on a second thread, 4 scans in
  // flight.
  AsyncRecordWriter scans_writer(proto::Scan::default_instance(), 4);
  TILTCAL_RETURN_IF_ERROR(OpenScansWriter(paths, params, provenance, &scans_writer));
  ImuSink imu(paths.bag, reader.MessageCount(s.imu_topic));
  ScanSink scans(paths.bag, params, s.lidar_type, &scans_writer);
  {
    ProgressLine progress(log, reader.MessageCount(s.imu_topic) +
                                   reader.MessageCount(s.lidar_topic));
    TILTCAL_RETURN_IF_ERROR(
        reader.ReadMessages(options, [&](const bag::Message& m) -> Status {
          progress.Update(m.sequence);
          return *m.topic == s.imu_topic ? imu.Add(m, &s) : scans.Add(m, &s);
        }));
  }
  TILTCAL_RETURN_IF_ERROR(CheckSomethingWritten(paths.bag, imu, s));
  imu.SortAndDropRepeatedStamps(&s);
  TILTCAL_RETURN_IF_ERROR(imu.CheckStampGaps(params.max_stamp_gap_s()));
  TILTCAL_RETURN_IF_ERROR(CheckStampsAndUnits(paths, params, rig, imu, scans, &s));
  TILTCAL_RETURN_IF_ERROR(imu.CheckPhysicalRange(params.imu_range(), s.accel_to_si, s.gyro_to_si));
  proto::Provenance imu_provenance = provenance;
  for (const std::string& note : s.imu_notes) imu_provenance.add_notes(note);
  if (!s.clock_drift_note.empty()) imu_provenance.add_notes(timing::kClockDriftNotePrefix + s.clock_drift_note);
  RecordWriter imu_writer;
  TILTCAL_RETURN_IF_ERROR(
      imu.Write(paths.out_imu, imu_provenance, s.accel_to_si, s.gyro_to_si, &imu_writer, &s));
  TILTCAL_RETURN_IF_ERROR(scans_writer.Finish());
  // Both outputs or neither, also when the process is killed meanwhile.
  TILTCAL_RETURN_IF_ERROR(CommitTogether({imu_writer.file(), scans_writer.file()}));
  s.chunks_decompressed = reader.chunks_decompressed();
  s.duplicates_dropped = reader.duplicates_dropped();
  s.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  PrintSummary(log, paths, params, s);
  if (summary != nullptr) *summary = s;
  return Status::Ok();
}

Status Run(const DecodePaths& paths, const proto::DecodeParams& params, std::ostream* log) {
  return Decode(paths, params, log, nullptr);
}

}  // namespace tiltcal
