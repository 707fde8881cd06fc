#include "stages/decode/decode.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <vector>

#include "common/io/provenance.h"
#include "common/io/record_stream.h"
#include "common/io/text_proto.h"
#include "stages/decode/async_record_writer.h"
#include "stages/decode/point_cloud_conversion.h"
#include "stages/decode/ros1_bag_reader.h"
#include "stages/decode/ros1_messages.h"
#include "tiltcal/proto/imu.pb.h"
#include "tiltcal/proto/rig.pb.h"
#include "tiltcal/proto/scan.pb.h"

namespace tiltcal {

namespace {

using Clock = std::chrono::steady_clock;

// ns -> "sec.nnnnnnnnn" exactly (no rounding through a double).
std::string FormatSeconds(int64_t ns) {
  const bool negative = ns < 0;
  const uint64_t abs_ns = negative ? 0 - static_cast<uint64_t>(ns) : static_cast<uint64_t>(ns);
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), "%s%llu.%09llu", negative ? "-" : "",
                static_cast<unsigned long long>(abs_ns / 1000000000),
                static_cast<unsigned long long>(abs_ns % 1000000000));
  return buffer;
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out.empty() ? "(none)" : out;
}

// Chooses the topic of message type `type`: the params' topic, else the
// rig's, else the only topic of that type in the bag.
Status ChooseTopic(const ros1::Ros1BagReader& reader, const std::string& type,
                   const std::string& params_topic, const std::string& rig_topic,
                   const char* params_field, std::string* topic) {
  const std::vector<std::string> candidates = reader.TopicsOfType(type);
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
                           " from the " + origin + ") in the bag; " + type +
                           " topics: " + describe(candidates));
    }
    if (actual != type) {
      return Status::Error(reader.path() + ": topic '" + requested + "' (" + params_field +
                           " from the " + origin + ") has type " + actual + ", expected " +
                           type);
    }
    *topic = requested;
    return Status::Ok();
  }
  if (candidates.empty()) {
    return Status::Error(reader.path() + ": no " + type + " topic in the bag (topics: " +
                         Join(reader.Topics()) + ")");
  }
  if (candidates.size() > 1) {
    return Status::Error(reader.path() + ": several " + type + " topics: " +
                         describe(candidates) + "; choose one with " + params_field +
                         " in the params or the rig");
  }
  *topic = candidates[0];
  return Status::Ok();
}

// One IMU sample kept until the end (sorted by stamp before writing).
struct ImuRecord {
  int64_t stamp_ns;
  int64_t record_ns;
  double angular_velocity[3];
  double linear_acceleration[3];
};

bool SameValues(const ImuRecord& a, const ImuRecord& b) {
  for (int i = 0; i < 3; ++i) {
    if (a.angular_velocity[i] != b.angular_velocity[i] ||
        a.linear_acceleration[i] != b.linear_acceleration[i]) {
      return false;
    }
  }
  return true;
}

double RateHz(int64_t count, int64_t first_ns, int64_t last_ns) {
  if (count < 2 || last_ns <= first_ns) return 0.0;
  return static_cast<double>(count - 1) / (static_cast<double>(last_ns - first_ns) * 1e-9);
}

void PrintSummary(std::FILE* log, const DecodeInputs& in, const ros1::Ros1BagReader& reader,
                  const DecodeSummary& s) {
  if (log == nullptr) return;
  const double mb = static_cast<double>(s.bag_bytes) * 1e-6;
  std::fprintf(log, "tiltcal_decode: %s: %.1f MB, %s\n", in.bag_path.c_str(), mb,
               s.indexed ? "indexed" : "UNINDEXED (linear scan)");
  if (!s.indexed) {
    std::fprintf(log, "  salvaged %lld messages from the unindexed bag%s%s\n",
                 static_cast<long long>(s.salvaged_messages),
                 s.salvage_note.empty() ? "" : "; ", s.salvage_note.c_str());
  }
  std::fprintf(log,
               "  imu   '%s': %lld msgs, %lld written, %.2f Hz, stamps %s .. %s s (%.3f s); "
               "dropped %lld duplicate + %lld conflicting stamps\n",
               s.imu_topic.c_str(), static_cast<long long>(s.imu_messages),
               static_cast<long long>(s.imu_written),
               RateHz(s.imu_written, s.imu_first_stamp_ns, s.imu_last_stamp_ns),
               FormatSeconds(s.imu_first_stamp_ns).c_str(),
               FormatSeconds(s.imu_last_stamp_ns).c_str(),
               static_cast<double>(s.imu_last_stamp_ns - s.imu_first_stamp_ns) * 1e-9,
               static_cast<long long>(s.imu_duplicates_dropped),
               static_cast<long long>(s.imu_conflicting_dropped));
  std::fprintf(log,
               "  lidar '%s': %lld msgs, %lld written, %.2f Hz, stamps %s .. %s s (%.3f s); "
               "dropped %lld non-monotonic + %lld empty scans\n",
               s.lidar_topic.c_str(), static_cast<long long>(s.scan_messages),
               static_cast<long long>(s.scans_written),
               RateHz(s.scans_written, s.scan_first_stamp_ns, s.scan_last_stamp_ns),
               FormatSeconds(s.scan_first_stamp_ns).c_str(),
               FormatSeconds(s.scan_last_stamp_ns).c_str(),
               static_cast<double>(s.scan_last_stamp_ns - s.scan_first_stamp_ns) * 1e-9,
               static_cast<long long>(s.scans_non_monotonic_dropped),
               static_cast<long long>(s.scans_empty_dropped));
  std::fprintf(log, "  points: %lld written; dropped %lld NaN/Inf, %lld zero/short range\n",
               static_cast<long long>(s.points_written),
               static_cast<long long>(s.points_dropped_invalid),
               static_cast<long long>(s.points_dropped_range));
  if (s.scans_without_point_time > 0) {
    std::fprintf(log,
                 "  WARNING: %lld scans have no per-point time field (time_source "
                 "POINT_TIME_NONE): they cannot be deskewed\n",
                 static_cast<long long>(s.scans_without_point_time));
  }
  std::fprintf(log, "  wall %.3f s, %.1f MB/s, %llu chunks decompressed\n", s.wall_s,
               s.wall_s > 0 ? mb / s.wall_s : 0.0,
               static_cast<unsigned long long>(s.chunks_decompressed));
}

}  // namespace

Status Run(const DecodeInputs& in, const proto::DecodeParams& params, DecodeSummary* summary_out) {
  const Clock::time_point t0 = Clock::now();
  DecodeSummary s;
  if (in.bag_path.empty()) return Status::Error("no input bag (--bag)");
  if (in.out_imu_path.empty()) return Status::Error("no IMU output path (--out_imu)");
  if (in.out_scans_path.empty()) return Status::Error("no scan output path (--out_scans)");
  if (in.out_imu_path == in.out_scans_path) {
    return Status::Error("--out_imu and --out_scans name the same file " + in.out_imu_path);
  }

  proto::Rig rig;
  if (!in.rig_path.empty()) TILTCAL_RETURN_IF_ERROR(ReadTextProto(in.rig_path, &rig));

  ros1::Ros1BagReader reader;
  TILTCAL_RETURN_IF_ERROR(reader.Open(in.bag_path));
  s.bag_bytes = reader.file_size();
  s.indexed = reader.indexed();
  s.salvaged_messages = reader.num_salvaged_messages();
  s.salvage_note = reader.salvage_note();
  if (reader.TotalMessageCount() == 0) {
    return Status::Error(in.bag_path + ": the bag holds no messages" +
                         (s.salvage_note.empty() ? "" : " (" + s.salvage_note + ")"));
  }
  TILTCAL_RETURN_IF_ERROR(ChooseTopic(reader, ros1::kImuType, params.imu_topic(),
                                      rig.imu_topic(), "imu_topic", &s.imu_topic));
  TILTCAL_RETURN_IF_ERROR(ChooseTopic(reader, ros1::kPointCloud2Type, params.lidar_topic(),
                                      rig.lidar_topic(), "lidar_topic", &s.lidar_topic));
  if (s.imu_topic == s.lidar_topic) {
    return Status::Error(in.bag_path + ": imu and lidar topic are the same: " + s.imu_topic);
  }

  // Time window on record time, relative to the bag's first message.
  ros1::ReadOptions options;
  options.topics = {s.imu_topic, s.lidar_topic};
  options.chunk_cache_size = std::max<uint32_t>(params.chunk_cache_size(), 1);
  int64_t bag_start_ns = 0;
  int64_t bag_end_ns = 0;
  (void)reader.TimeRange(&bag_start_ns, &bag_end_ns);
  if (params.start_offset_s() > 0 || params.duration_s() > 0) {
    options.start_ns = bag_start_ns + std::llround(params.start_offset_s() * 1e9);
    if (params.duration_s() > 0) {
      options.end_ns = options.start_ns + std::llround(params.duration_s() * 1e9);
    }
    if (options.start_ns > bag_end_ns) {
      return Status::Error(in.bag_path + ": start_offset_s " +
                           std::to_string(params.start_offset_s()) +
                           " is past the end of the bag (" +
                           std::to_string(static_cast<double>(bag_end_ns - bag_start_ns) * 1e-9) +
                           " s long)");
    }
  }

  std::vector<InputPath> input_paths = {{"bag", in.bag_path}};
  if (!in.rig_path.empty()) input_paths.push_back({"rig", in.rig_path});
  const proto::Provenance provenance =
      MakeProvenance("tiltcal_decode", params, input_paths, in.command_line);

  // Scans are compressed and written on a second thread, 4 scans in flight.
  AsyncRecordWriter scans_writer(proto::Scan::default_instance(), 4);
  TILTCAL_RETURN_IF_ERROR(scans_writer.Open(in.out_scans_path,
                                            proto::Scan::descriptor()->full_name(), provenance,
                                            /*compress=*/true));

  const bool progress = in.log != nullptr && ::isatty(::fileno(in.log));
  const int64_t total = reader.MessageCount(s.imu_topic) + reader.MessageCount(s.lidar_topic);
  Clock::time_point last_progress = t0;

  PointConversionOptions conversion;
  conversion.min_range_m = params.min_range_m();
  std::vector<ImuRecord> imu;
  imu.reserve(static_cast<size_t>(std::max<int64_t>(reader.MessageCount(s.imu_topic), 0)));
  ros1::ImuMessage imu_message;
  ros1::PointCloud2View cloud;
  int64_t last_scan_stamp_ns = INT64_MIN;

  auto on_message = [&](const ros1::MessageView& m) -> Status {
    const bool is_imu = m.connection->topic == s.imu_topic;
    const int64_t index = is_imu ? s.imu_messages++ : s.scan_messages++;
    auto context = [&]() {
      return in.bag_path + ": topic '" + m.connection->topic + "' message " +
             std::to_string(index) + " (record time " + FormatSeconds(m.time_ns) +
             " s, chunk at byte " + std::to_string(m.chunk_pos) + ")";
    };
    if (progress && (m.sequence & 255) == 0) {
      const Clock::time_point now = Clock::now();
      if (now - last_progress > std::chrono::milliseconds(250)) {
        last_progress = now;
        std::fprintf(in.log, "\rtiltcal_decode: %3.0f%% (%llu / %lld messages)",
                     total > 0 ? 100.0 * static_cast<double>(m.sequence) / total : 0.0,
                     static_cast<unsigned long long>(m.sequence), static_cast<long long>(total));
        std::fflush(in.log);
      }
    }
    if (is_imu) {
      Status status = ros1::DecodeImu(m.data, m.size, &imu_message);
      if (!status.ok()) return status.WithContext(context() + ": sensor_msgs/Imu");
      ImuRecord r;
      r.stamp_ns = ros1::RosTimeToNs(imu_message.header.stamp);
      r.record_ns = m.time_ns;
      for (int i = 0; i < 3; ++i) {
        r.angular_velocity[i] = imu_message.angular_velocity[i];
        r.linear_acceleration[i] = imu_message.linear_acceleration[i];
        if (!std::isfinite(r.angular_velocity[i]) || !std::isfinite(r.linear_acceleration[i])) {
          return Status::Error(context() + ": sensor_msgs/Imu has a NaN or Inf angular "
                                           "velocity or linear acceleration");
        }
      }
      imu.push_back(r);
      return Status::Ok();
    }
    auto* scan_ptr = static_cast<proto::Scan*>(scans_writer.Acquire());
    proto::Scan& scan = *scan_ptr;
    bool submitted = false;
    // Gives the record back unless it was handed to the writer.
    struct Releaser {
      AsyncRecordWriter* writer;
      proto::Scan* scan;
      const bool* submitted;
      ~Releaser() {
        if (!*submitted) writer->Release(scan);
      }
    } releaser{&scans_writer, scan_ptr, &submitted};
    Status status = ros1::DecodePointCloud2(m.data, m.size, &cloud);
    if (status.ok()) status = ConvertPointCloud2ToScan(cloud, conversion, &scan);
    if (!status.ok()) return status.WithContext(context() + ": sensor_msgs/PointCloud2");
    s.points_dropped_invalid += scan.num_dropped_invalid();
    s.points_dropped_range += scan.num_dropped_zero_range();
    if (scan.time_source() == proto::POINT_TIME_NONE) {
      if (params.require_point_time()) {
        return Status::Error(context() + ": sensor_msgs/PointCloud2 has no per-point time "
                                         "field (fields: " + DescribeFields(cloud) +
                             ") and require_point_time is set");
      }
      ++s.scans_without_point_time;
    }
    if (scan.x_size() == 0) {
      ++s.scans_empty_dropped;
      return Status::Ok();
    }
    if (scan.stamp_ns() <= last_scan_stamp_ns) {
      if (!params.drop_non_monotonic()) {
        return Status::Error(context() + ": scan stamp " + FormatSeconds(scan.stamp_ns()) +
                             " s is not after the previous scan's " +
                             FormatSeconds(last_scan_stamp_ns) +
                             " s (set drop_non_monotonic to drop such scans)");
      }
      ++s.scans_non_monotonic_dropped;
      return Status::Ok();
    }
    last_scan_stamp_ns = scan.stamp_ns();
    scan.set_index(static_cast<uint32_t>(s.scans_written));
    scan.set_record_stamp_ns(m.time_ns);
    if (s.scans_written == 0) s.scan_first_stamp_ns = scan.stamp_ns();
    s.scan_last_stamp_ns = scan.stamp_ns();
    ++s.scans_written;
    s.points_written += scan.x_size();
    submitted = true;
    return scans_writer.Submit(scan_ptr);
  };
  Status status = reader.ReadMessages(options, on_message);
  if (progress) std::fprintf(in.log, "\r\033[K");
  TILTCAL_RETURN_IF_ERROR(status);

  if (s.scans_written == 0) {
    return Status::Error(in.bag_path + ": no usable scan on topic '" + s.lidar_topic + "' (" +
                         std::to_string(s.scan_messages) + " messages in the window, " +
                         std::to_string(s.scans_empty_dropped) + " without valid points)");
  }
  if (imu.empty()) {
    return Status::Error(in.bag_path + ": no IMU message on topic '" + s.imu_topic +
                         "' in the time window");
  }

  // IMU: sort by stamp (stable: record order among equal stamps), drop
  // repeated stamps, write.
  std::stable_sort(imu.begin(), imu.end(), [](const ImuRecord& a, const ImuRecord& b) {
    return a.stamp_ns < b.stamp_ns;
  });
  RecordWriter imu_writer;
  TILTCAL_RETURN_IF_ERROR(imu_writer.Open(in.out_imu_path,
                                          proto::ImuSample::descriptor()->full_name(),
                                          provenance, /*compress=*/false));
  proto::ImuSample sample;
  for (size_t i = 0; i < imu.size(); ++i) {
    const ImuRecord& r = imu[i];
    if (i > 0 && r.stamp_ns == imu[i - 1].stamp_ns) {
      // Compare with the kept sample of this stamp (the first one).
      size_t first = i - 1;
      while (first > 0 && imu[first - 1].stamp_ns == r.stamp_ns) --first;
      if (SameValues(r, imu[first])) {
        ++s.imu_duplicates_dropped;
      } else {
        ++s.imu_conflicting_dropped;
      }
      continue;
    }
    sample.set_stamp_ns(r.stamp_ns);
    sample.set_record_stamp_ns(r.record_ns);
    auto* w = sample.mutable_angular_velocity_radps();
    w->set_x(r.angular_velocity[0]);
    w->set_y(r.angular_velocity[1]);
    w->set_z(r.angular_velocity[2]);
    auto* a = sample.mutable_linear_acceleration_mps2();
    a->set_x(r.linear_acceleration[0]);
    a->set_y(r.linear_acceleration[1]);
    a->set_z(r.linear_acceleration[2]);
    TILTCAL_RETURN_IF_ERROR(imu_writer.Write(sample));
    if (s.imu_written == 0) s.imu_first_stamp_ns = r.stamp_ns;
    s.imu_last_stamp_ns = r.stamp_ns;
    ++s.imu_written;
  }
  TILTCAL_RETURN_IF_ERROR(imu_writer.Close());
  status = scans_writer.Close();
  if (!status.ok()) {
    std::remove(in.out_imu_path.c_str());  // both outputs or none
    return status;
  }
  s.chunks_decompressed = reader.stats().chunks_decompressed;
  s.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  PrintSummary(in.log, in, reader, s);
  if (summary_out != nullptr) *summary_out = s;
  return Status::Ok();
}

}  // namespace tiltcal
