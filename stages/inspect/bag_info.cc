#include "stages/inspect/bag_info.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <unordered_map>

#include <fmt/format.h>

#include "bag/input/bag_input.h"
#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"

namespace tiltcal::inspect {
namespace {

namespace fs = std::filesystem;

// A metadata.yaml larger than this is no rosbag2 metadata.
constexpr uintmax_t kMaxMetadataBytes = uintmax_t{1} << 20;

bool IsRos1SensorType(const std::string& type) {
  for (const char* t : {ros1::kImuType, ros1::kPointCloud2Type, ros1::kLivoxCustomMsgType,
                        ros1::kLivox2CustomMsgType, ros1::kTfMessageType,
                        ros1::kTfLegacyMessageType}) {
    if (type == t) return true;
  }
  return false;
}

bool IsRos2SensorType(const std::string& type) {
  for (const char* t : {ros2::kImuType, ros2::kPointCloud2Type, ros2::kLivox2CustomMsgType,
                        ros2::kLivoxInterfacesCustomMsgType, ros2::kTfMessageType}) {
    if (type == t) return true;
  }
  return false;
}

// Deserialises `m` of a sensor type `type` with the decoder of its encoding.
Status DecodeSensorMessage(const std::string& type, const bag::Message& m) {
  if (m.encoding == bag::Encoding::kRos1) {
    if (!IsRos1SensorType(type)) return Status::Error("a ROS 2 type in the ROS 1 encoding");
    if (type == ros1::kImuType) {
      bag::ImuMessage imu;
      return ros1::DecodeImu(m.data, m.size, &imu);
    }
    if (type == ros1::kPointCloud2Type) {
      bag::PointCloud2View cloud;
      return ros1::DecodePointCloud2(m.data, m.size, &cloud);
    }
    if (type == ros1::kTfMessageType || type == ros1::kTfLegacyMessageType) {
      bag::TfMessage tf;
      return ros1::DecodeTfMessage(m.data, m.size, &tf);
    }
    bag::LivoxCustomMessage livox;
    return ros1::DecodeLivoxCustomMsg(m.data, m.size, &livox);
  }
  if (!IsRos2SensorType(type)) return Status::Error("a ROS 1 type in the CDR encoding");
  if (type == ros2::kImuType) {
    bag::ImuMessage imu;
    return ros2::DecodeImu(m.data, m.size, &imu);
  }
  if (type == ros2::kPointCloud2Type) {
    bag::PointCloud2View cloud;
    return ros2::DecodePointCloud2(m.data, m.size, &cloud);
  }
  if (type == ros2::kTfMessageType) {
    bag::TfMessage tf;
    return ros2::DecodeTfMessage(m.data, m.size, &tf);
  }
  bag::LivoxCustomMessage livox;
  return ros2::DecodeLivoxCustomMsg(m.data, m.size, &livox);
}

// 1 / the median interval of `times_ns` (in record order), as rosbag's
// get_type_and_topic_info: the middle interval, or the mean of the two
// middle ones for an even number; 0 with fewer than two times or a zero
// median.
double RateFromRecordTimes(const std::vector<int64_t>& times_ns) {
  if (times_ns.size() < 2) return 0.0;
  std::vector<int64_t> intervals;
  intervals.reserve(times_ns.size() - 1);
  for (size_t i = 1; i < times_ns.size(); ++i) intervals.push_back(times_ns[i] - times_ns[i - 1]);
  std::sort(intervals.begin(), intervals.end());
  const size_t n = intervals.size();
  const double median_ns =
      n % 2 == 1 ? static_cast<double>(intervals[n / 2])
                 : 0.5 * (static_cast<double>(intervals[n / 2 - 1]) +
                          static_cast<double>(intervals[n / 2]));
  return median_ns > 0.0 ? 1e9 / median_ns : 0.0;
}

// The text of the metadata.yaml at `path`: a regular file of at most
// kMaxMetadataBytes.
Status ReadMetadataText(const std::string& path, std::string* text) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Status::Error(path + ": not a regular file");
  const uintmax_t size = fs::file_size(path, ec);
  if (ec || size > kMaxMetadataBytes) {
    return Status::Error(path + ": larger than " + std::to_string(kMaxMetadataBytes) +
                         " bytes: no rosbag2 metadata");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (!in) return Status::Error(path + ": cannot read");
  *text = buffer.str();
  return Status::Ok();
}

// The disagreements of metadata.yaml with the files.
void CompareWithMetadata(BagInfo* info) {
  const ros2::Rosbag2Figures& m = info->metadata;
  auto warn = [info](const std::string& what) { info->warnings.push_back("metadata.yaml: " + what); };
  for (const std::string& value : m.unreadable) warn("unreadable value '" + value + "'");
  if (m.message_count >= 0 && m.message_count != info->message_count) {
    warn(fmt::format("{} messages, the files hold {}", m.message_count, info->message_count));
  }
  if (info->message_count > 0 && m.starting_time_ns >= 0 && m.starting_time_ns != info->first_ns) {
    warn(fmt::format("starting_time {} ns, the first message is at {} ns", m.starting_time_ns,
                     info->first_ns));
  }
  if (info->message_count > 0 && m.duration_ns >= 0 &&
      m.duration_ns != info->last_ns - info->first_ns) {
    warn(fmt::format("duration {} ns, the messages span {} ns", m.duration_ns,
                     info->last_ns - info->first_ns));
  }
  for (const ros2::Rosbag2TopicFigures& t : m.topics) {
    const auto it = std::find_if(info->topics.begin(), info->topics.end(),
                                 [&](const TopicFigures& f) { return f.name == t.name; });
    if (it == info->topics.end()) {
      warn(fmt::format("topic '{}' ({} messages) is not in the files", t.name, t.message_count));
      continue;
    }
    if (t.type != it->type) {
      warn(fmt::format("topic '{}' is {}, the files say {}", t.name, t.type, it->type));
    }
    if (t.message_count >= 0 && t.message_count != it->count) {
      warn(fmt::format("topic '{}': {} messages, the files hold {}", t.name, t.message_count,
                       it->count));
    }
    if (!t.serialization_format.empty() && !it->encoding.empty() &&
        t.serialization_format != it->encoding) {
      warn(fmt::format("topic '{}' serialised as '{}', the files hold {}", t.name,
                       t.serialization_format, it->encoding));
    }
  }
  for (const TopicFigures& f : info->topics) {
    const bool listed = std::any_of(m.topics.begin(), m.topics.end(),
                                    [&](const ros2::Rosbag2TopicFigures& t) { return t.name == f.name; });
    if (!listed) warn(fmt::format("does not list topic '{}' ({} messages)", f.name, f.count));
  }
}

// Counts message `m` in the figures of its topic, and deserialises it when
// its type is a sensor's.
void CountMessage(const bag::Message& m, TopicFigures* f) {
  if (f->count == 0) f->first_ns = m.time_ns;
  f->last_ns = m.time_ns;
  ++f->count;
  f->encoding = m.encoding == bag::Encoding::kRos1 ? "ros1" : "cdr";
  if (!f->sensor_type) return;
  const Status decoded = DecodeSensorMessage(f->type, m);
  if (decoded.ok()) {
    ++f->decoded;
  } else if (f->decode_failures++ == 0) {
    f->decode_error = fmt::format("message {} ({}): {}", f->count - 1, bag::DescribePosition(m),
                                  decoded.message());
  }
}

// The warnings of the reading: salvage, what the reader left out (damaged
// records, unlisted files, bad rows: `reader_warnings`), duplicates, counts
// that differ from the index, messages that do not deserialise.
void AddReadWarnings(const std::vector<std::string>& reader_warnings, BagInfo* info) {
  if (!info->salvage_note.empty()) info->warnings.push_back("salvaged: " + info->salvage_note);
  for (const std::string& w : reader_warnings) info->warnings.push_back("reader: " + w);
  if (info->duplicates_dropped > 0) {
    info->warnings.push_back(fmt::format(
        "{} messages held by two files of the folder (same topic, time and bytes) counted once",
        info->duplicates_dropped));
  }
  for (const TopicFigures& f : info->topics) {
    // (The duplicates a folder's merge drops are in its files' counts.)
    if (info->duplicates_dropped == 0 && f.count != f.indexed_count) {
      info->warnings.push_back(fmt::format("topic '{}': the index counts {} messages, {} were read",
                                           f.name, f.indexed_count, f.count));
    }
    if (f.decode_failures > 0) {
      info->warnings.push_back(fmt::format("topic '{}': {} of {} messages do not deserialise as {}; "
                                           "the first: {}",
                                           f.name, f.decode_failures, f.count, f.type,
                                           f.decode_error));
    }
  }
}

}  // namespace

Status ReadBagInfo(const std::string& path, BagInfo* info) {
  *info = BagInfo();
  info->path = path;
  std::unique_ptr<bag::MessageReader> reader;
  TILTCAL_RETURN_IF_ERROR(bag::OpenBagInput(path, bag::Ros1ChunkSettings(), &reader));
  info->format = reader->format_name();
  info->files = reader->input_files();
  info->size_bytes = reader->size_bytes();
  info->indexed = reader->indexed();
  TILTCAL_RETURN_IF_ERROR(reader->ChunkCompressions(&info->chunk_compressions));

  std::unordered_map<std::string, size_t> index_of;
  for (const bag::TopicInfo& t : reader->topics()) {
    index_of[t.name] = info->topics.size();
    TopicFigures f;
    f.name = t.name;
    f.type = t.type;
    f.indexed_count = t.message_count;
    f.sensor_type = IsRos1SensorType(t.type) || IsRos2SensorType(t.type);
    info->topics.push_back(std::move(f));
  }
  std::vector<std::vector<int64_t>> times(info->topics.size());
  TILTCAL_RETURN_IF_ERROR(reader->ReadMessages({}, [&](const bag::Message& m) {
    const auto it = index_of.find(*m.topic);
    if (it == index_of.end()) {
      return Status::Error(fmt::format("{}: a message of topic '{}', which the reader did not list",
                                       path, *m.topic));
    }
    times[it->second].push_back(m.time_ns);
    CountMessage(m, &info->topics[it->second]);
    return Status::Ok();
  }));
  info->salvage_note = reader->salvage_note();
  info->duplicates_dropped = reader->duplicates_dropped();

  for (size_t i = 0; i < info->topics.size(); ++i) {
    TopicFigures& f = info->topics[i];
    f.rate_hz = RateFromRecordTimes(times[i]);
    if (f.count == 0) continue;
    info->first_ns = info->message_count == 0 ? f.first_ns : std::min(info->first_ns, f.first_ns);
    info->last_ns = info->message_count == 0 ? f.last_ns : std::max(info->last_ns, f.last_ns);
    info->message_count += f.count;
  }
  AddReadWarnings(reader->warnings(), info);

  std::error_code ec;
  const fs::path metadata = fs::path(path) / "metadata.yaml";
  if (fs::is_directory(path, ec) && fs::exists(metadata, ec)) {
    std::string text;
    TILTCAL_RETURN_IF_ERROR(ReadMetadataText(metadata.string(), &text));
    info->has_metadata = true;
    info->metadata_path = metadata.string();
    info->metadata = ros2::ParseRosbag2Figures(text);
    CompareWithMetadata(info);
  }
  return Status::Ok();
}

}  // namespace tiltcal::inspect
