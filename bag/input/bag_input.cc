#include "bag/input/bag_input.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "bag/mcap/mcap_reader.h"
#include "bag/merged_message_reader.h"
#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"
#include "bag/ros2/sqlite_bag_reader.h"
#include "bag/input/ros1_message_reader.h"

namespace tiltcal::bag {

namespace fs = std::filesystem;

namespace {

// The first 16 bytes of every sqlite3 database file.
constexpr char kSqliteMagic[16] = {'S', 'Q', 'L', 'i', 't', 'e', ' ', 'f',
                                   'o', 'r', 'm', 'a', 't', ' ', '3', '\0'};
constexpr char kShapes[] =
    "a .bag (ROS 1), a .mcap, a .db3, a ROS 2 bag folder with metadata.yaml, or a folder of "
    ".bag / .mcap / .db3 files";

// The storage_identifier of a rosbag2 metadata.yaml ("sqlite3", "mcap"),
// and its relative_file_paths entries.
void ReadStorage(const std::string& metadata, std::string* storage,
                 std::vector<std::string>* files) {
  std::ifstream in(metadata);
  bool in_list = false;
  for (std::string line; std::getline(in, line);) {
    const size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos) continue;
    std::string t = line.substr(start);
    t.erase(t.find_last_not_of(" \t\r") + 1);
    if (in_list && t.rfind("- ", 0) == 0) {
      files->push_back(t.substr(2));
      continue;
    }
    in_list = t.rfind("relative_file_paths:", 0) == 0;
    if (t.rfind("storage_identifier:", 0) == 0) {
      *storage = t.substr(19);
      storage->erase(0, storage->find_first_not_of(" \t\"'"));
      storage->erase(storage->find_last_not_of(" \t\"'") + 1);
    }
  }
}

// The bag files directly in `folder` (.bag, .mcap, .db3), in name order.
std::vector<std::string> BagFilesIn(const fs::path& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file(ec) && (ext == ".bag" || ext == ".mcap" || ext == ".db3")) {
      files.push_back(e.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

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
                 const Ros1ChunkSettings& ros1_chunks, std::unique_ptr<MessageReader>* reader) {
  if (files.size() == 1) return OpenBagFile(files[0], ros1_chunks, reader);
  std::vector<std::unique_ptr<MessageReader>> readers(files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    TILTCAL_RETURN_IF_ERROR(OpenBagFile(files[i], ros1_chunks, &readers[i]));
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
                    std::unique_ptr<MessageReader>* reader) {
  std::error_code ec;
  const fs::path p(path);
  if (!fs::is_directory(p, ec)) return OpenBagFile(path, ros1_chunks, reader);
  const fs::path metadata = p / "metadata.yaml";
  if (!fs::exists(metadata, ec)) {
    const std::vector<std::string> files = BagFilesIn(p);
    if (files.empty()) {
      return Status::Error(path + ": a folder with neither metadata.yaml nor bag files; expected " +
                           kShapes);
    }
    return OpenFiles(path, files, ros1_chunks, reader);
  }
  std::string storage;
  std::vector<std::string> relative_files;
  ReadStorage(metadata.string(), &storage, &relative_files);
  if (storage == "mcap") {
    if (relative_files.empty()) {
      return Status::Error(metadata.string() + ": no relative_file_paths");
    }
    std::vector<std::string> files;
    for (const std::string& f : relative_files) {
      files.push_back((p / fs::path(f).filename()).string());
    }
    return OpenFiles(path, files, ros1_chunks, reader);
  }
  if (!storage.empty() && storage != "sqlite3") {
    return Status::Error(metadata.string() + ": storage_identifier '" + storage +
                         "' (known: sqlite3, mcap)");
  }
  return OpenWith(std::make_unique<ros2::SqliteBagReader>(), path, reader);
}

Status OpenBagFile(const std::string& path, const Ros1ChunkSettings& ros1_chunks,
                   std::unique_ptr<MessageReader>* reader) {
  // A file is recognised by its first bytes, whatever its name; anything
  // that is neither MCAP nor sqlite3 goes to the ROS 1 reader, whose errors
  // say what is wrong with it.
  char head[16] = {};
  std::ifstream(path, std::ios::binary).read(head, sizeof(head));
  if (std::memcmp(head, mcap::kMagic, sizeof(mcap::kMagic)) == 0) {
    return OpenWith(std::make_unique<mcap::McapReader>(), path, reader);
  }
  if (std::memcmp(head, kSqliteMagic, sizeof(kSqliteMagic)) == 0) {
    return OpenWith(std::make_unique<ros2::SqliteBagReader>(), path, reader);
  }
  return OpenWith(std::make_unique<Ros1MessageReader>(ros1_chunks.cache_size,
                                                     ros1_chunks.read_ahead), path, reader);
}

}  // namespace tiltcal::bag
