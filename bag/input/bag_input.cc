#include "bag/input/bag_input.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "bag/mcap/mcap_reader.h"
#include "bag/merged_message_reader.h"
#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"
#include "bag/ros2/rosbag2_metadata.h"
#include "bag/ros2/sqlite_bag_reader.h"
#include "bag/input/ros1_message_reader.h"
#include "common/io/input_file.h"

namespace tiltcal::bag {

namespace fs = std::filesystem;

namespace {

// The first 16 bytes of every sqlite3 database file.
constexpr char kSqliteMagic[16] = {'S', 'Q', 'L', 'i', 't', 'e', ' ', 'f',
                                   'o', 'r', 'm', 'a', 't', ' ', '3', '\0'};
constexpr char kShapes[] =
    "a .bag (ROS 1), a .mcap, a .db3, a ROS 2 bag folder with metadata.yaml, or a folder of "
    ".bag / .mcap / .db3 files";

// The bag files directly in `folder` (.bag, .mcap, .db3), in name order.
// Sub-folders are not read; any other entry named like a bag that is not a
// regular file (a dangling symbolic link, a link loop, a FIFO, a device) is
// an error naming it.
Status BagFilesIn(const fs::path& folder, std::vector<std::string>* files) {
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    const std::string ext = e.path().extension().string();
    if (ext != ".bag" && ext != ".mcap" && ext != ".db3") continue;
    std::error_code status_error;
    const fs::file_status status = fs::status(e.path(), status_error);
    if (fs::is_directory(status)) continue;
    if (fs::is_regular_file(status)) {
      files->push_back(e.path().string());
      continue;
    }
    const bool link = fs::is_symlink(fs::symlink_status(e.path(), ec));
    if (link && status_error.value() == ELOOP) {
      return Status::Error(e.path().string() + ": a symbolic link loop, not a bag file");
    }
    if (link && !fs::exists(status)) {
      std::error_code target_error;
      return Status::Error(e.path().string() + ": a symbolic link to " +
                           fs::read_symlink(e.path(), target_error).string() +
                           ", which does not exist");
    }
    TILTCAL_RETURN_IF_ERROR(CheckInputFile(e.path().string()));
  }
  if (ec) return Status::Error(folder.string() + ": cannot list: " + ec.message());
  std::sort(files->begin(), files->end());
  return Status::Ok();
}

// A reader with the warnings of the folder around it (files it does not
// read), everything else the reader's own.
class FolderWarnings : public MessageReader {
 public:
  FolderWarnings(std::string path, std::unique_ptr<MessageReader> reader,
                 std::vector<std::string> warnings)
      : path_(std::move(path)), reader_(std::move(reader)), warnings_(std::move(warnings)) {}
  const std::string& path() const override { return path_; }
  std::vector<std::string> input_files() const override { return reader_->input_files(); }
  uint64_t size_bytes() const override { return reader_->size_bytes(); }
  std::string format_name() const override { return reader_->format_name(); }
  bool indexed() const override { return reader_->indexed(); }
  int64_t num_salvaged_messages() const override { return reader_->num_salvaged_messages(); }
  std::string salvage_note() const override { return reader_->salvage_note(); }
  std::vector<std::string> warnings() const override {
    std::vector<std::string> all = warnings_;
    for (std::string& w : reader_->warnings()) all.push_back(std::move(w));
    return all;
  }
  uint64_t chunks_decompressed() const override { return reader_->chunks_decompressed(); }
  int64_t duplicates_dropped() const override { return reader_->duplicates_dropped(); }
  const std::vector<TopicInfo>& topics() const override { return reader_->topics(); }
  bool TimeRange(int64_t* start_ns, int64_t* end_ns) const override {
    return reader_->TimeRange(start_ns, end_ns);
  }
  Status ReadMessages(const MessageSelection& selection,
                      const std::function<Status(const Message&)>& fn) override {
    return reader_->ReadMessages(selection, fn);
  }

 private:
  std::string path_;
  std::unique_ptr<MessageReader> reader_;
  std::vector<std::string> warnings_;
};

template <typename Reader>
Status OpenWith(std::unique_ptr<Reader> r, const std::string& path,
                std::unique_ptr<MessageReader>* reader) {
  TILTCAL_RETURN_IF_ERROR(r->Open(path));
  *reader = std::move(r);
  return Status::Ok();
}

// Opens every file of `files` (each by its first bytes) and merges them;
// a single file is opened alone.
Status OpenFiles(const std::string& path, const std::vector<std::string>& files,
                 const Ros1ChunkSettings& ros1_chunks, const ReaderLimits& limits,
                 std::unique_ptr<MessageReader>* reader) {
  if (files.size() == 1) return OpenBagFile(files[0], ros1_chunks, reader, limits);
  std::vector<std::unique_ptr<MessageReader>> readers(files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    TILTCAL_RETURN_IF_ERROR(OpenBagFile(files[i], ros1_chunks, &readers[i], limits));
  }
  auto merged = std::make_unique<MergedMessageReader>();
  TILTCAL_RETURN_IF_ERROR(merged->Open(path, std::move(readers)));
  *reader = std::move(merged);
  return Status::Ok();
}

}  // namespace

std::vector<std::string> SensorTypes::Lidar() const {
  std::vector<std::string> types = {point_cloud2};
  types.insert(types.end(), livox.begin(), livox.end());
  return types;
}

SensorTypes SensorTypesOf(const MessageReader& reader) {
  const SensorTypes ros1_types = {ros1::kImuType,
                                  ros1::kPointCloud2Type,
                                  {ros1::kLivoxCustomMsgType, ros1::kLivox2CustomMsgType},
                                  {ros1::kTfMessageType, ros1::kTfLegacyMessageType}};
  const SensorTypes ros2_types = {
      ros2::kImuType,
      ros2::kPointCloud2Type,
      {ros2::kLivox2CustomMsgType, ros2::kLivoxInterfacesCustomMsgType},
      {ros2::kTfMessageType}};
  // A ROS 1 bag, or an MCAP with the ROS 1 type names, is read as ROS 1.
  for (const TopicInfo& t : reader.topics()) {
    for (const std::string& type : ros1_types.Lidar()) {
      if (t.type == ros1::kImuType || t.type == type) return ros1_types;
    }
  }
  if (reader.format_name() == "ROS 1 bag") return ros1_types;
  return ros2_types;
}

Status OpenBagInput(const std::string& path, const Ros1ChunkSettings& ros1_chunks,
                    std::unique_ptr<MessageReader>* reader, const ReaderLimits& limits) {
  std::error_code ec;
  const fs::path p(path);
  if (!fs::is_directory(p, ec)) return OpenBagFile(path, ros1_chunks, reader, limits);
  const fs::path metadata = p / "metadata.yaml";
  if (!fs::exists(fs::symlink_status(metadata, ec))) {
    std::vector<std::string> files;
    TILTCAL_RETURN_IF_ERROR(BagFilesIn(p, &files));
    if (files.empty()) {
      return Status::Error(path + ": a folder with neither metadata.yaml nor bag files; expected " +
                           kShapes);
    }
    return OpenFiles(path, files, ros1_chunks, limits, reader);
  }
  ros2::Rosbag2Metadata parsed;
  TILTCAL_RETURN_IF_ERROR(ros2::ReadRosbag2Metadata(metadata.string(), &parsed));
  const std::string& storage = parsed.storage_identifier;
  if (storage == "mcap") {
    if (!parsed.compression_format.empty()) {
      return Status::Error(metadata.string() + ": compression_format '" +
                           parsed.compression_format +
                           "': compressed rosbag2 bags are not supported (decompress them with "
                           "`ros2 bag convert`)");
    }
    if (parsed.relative_file_paths.empty()) {
      return Status::Error(metadata.string() + ": no relative_file_paths");
    }
    std::vector<std::string> files;
    for (const std::string& f : parsed.relative_file_paths) {
      const std::string file = (p / fs::path(f).filename()).string();
      if (!fs::exists(file, ec)) {
        return Status::Error(metadata.string() + ": lists '" + f + "', which is not in " + path);
      }
      files.push_back(file);
    }
    std::string unlisted;
    int num_unlisted = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(p, ec)) {
      if (e.path().extension() == ".mcap" &&
          std::find(files.begin(), files.end(), e.path().string()) == files.end()) {
        unlisted += (num_unlisted++ == 0 ? "" : ", ") + e.path().filename().string();
      }
    }
    std::unique_ptr<MessageReader> opened;
    TILTCAL_RETURN_IF_ERROR(OpenFiles(path, files, ros1_chunks, limits, &opened));
    if (num_unlisted == 0) {
      *reader = std::move(opened);
      return Status::Ok();
    }
    *reader = std::make_unique<FolderWarnings>(
        path, std::move(opened),
        std::vector<std::string>{path + ": " + std::to_string(num_unlisted) +
                                 " .mcap file(s) of the folder not listed in metadata.yaml, not "
                                 "read: " + unlisted});
    return Status::Ok();
  }
  if (!storage.empty() && storage != "sqlite3") {
    return Status::Error(metadata.string() + ": storage_identifier '" + storage +
                         "' (known: sqlite3, mcap)");
  }
  return OpenWith(std::make_unique<ros2::SqliteBagReader>(), path, reader);
}

Status OpenBagFile(const std::string& path, const Ros1ChunkSettings& ros1_chunks,
                   std::unique_ptr<MessageReader>* reader, const ReaderLimits& limits) {
  // A file is recognised by its first bytes, whatever its name; anything
  // that is neither MCAP nor sqlite3 goes to the ROS 1 reader, whose errors
  // say what is wrong with it. A FIFO or a device is refused first.
  int fd = -1;
  uint64_t size = 0;
  TILTCAL_RETURN_IF_ERROR(OpenInputFile(path, &fd, &size));
  char head[16] = {};
  const ssize_t got = ::pread(fd, head, sizeof(head), 0);
  ::close(fd);
  if (got < 0) return Status::Error(path + ": cannot read: " + std::strerror(errno));
  if (std::memcmp(head, mcap::kMagic, sizeof(mcap::kMagic)) == 0) {
    return OpenWith(std::make_unique<mcap::McapReader>(limits.max_chunk_bytes), path, reader);
  }
  if (std::memcmp(head, kSqliteMagic, sizeof(kSqliteMagic)) == 0) {
    return OpenWith(std::make_unique<ros2::SqliteBagReader>(), path, reader);
  }
  return OpenWith(std::make_unique<Ros1MessageReader>(ros1_chunks.cache_size,
                                                     ros1_chunks.read_ahead), path, reader);
}

}  // namespace tiltcal::bag
