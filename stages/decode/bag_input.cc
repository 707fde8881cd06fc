#include "stages/decode/bag_input.h"

#include <filesystem>
#include <cstring>
#include <fstream>

#include "bag/mcap/mcap_reader.h"
#include "bag/ros1/messages.h"
#include "bag/ros2/messages.h"
#include "bag/ros2/sqlite_bag_reader.h"
#include "stages/decode/ros1_message_reader.h"

namespace tiltcal::decode {

namespace fs = std::filesystem;

namespace {

// The first 16 bytes of every sqlite3 database file.
constexpr char kSqliteMagic[16] = {'S', 'Q', 'L', 'i', 't', 'e', ' ', 'f',
                                   'o', 'r', 'm', 'a', 't', ' ', '3', '\0'};
constexpr char kShapes[] =
    "a .bag (ROS 1), a .mcap, a .db3 or a ROS 2 bag folder with metadata.yaml";

// The storage_identifier of a rosbag2 metadata.yaml ("sqlite3", "mcap"),
// and its first relative_file_paths entry.
void ReadStorage(const std::string& metadata, std::string* storage, std::string* first_file) {
  std::ifstream in(metadata);
  bool in_list = false;
  for (std::string line; std::getline(in, line);) {
    const size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos) continue;
    const std::string t = line.substr(start);
    if (in_list && t.rfind("- ", 0) == 0 && first_file->empty()) {
      *first_file = t.substr(2);
      continue;
    }
    in_list = t.rfind("relative_file_paths:", 0) == 0;
    if (t.rfind("storage_identifier:", 0) == 0) {
      *storage = t.substr(19);
      storage->erase(0, storage->find_first_not_of(" \t\"'"));
      storage->erase(storage->find_last_not_of(" \t\"'\r") + 1);
    }
  }
}

template <typename Reader>
Status OpenWith(std::unique_ptr<Reader> r, const std::string& path,
                std::unique_ptr<bag::MessageReader>* reader) {
  TILTCAL_RETURN_IF_ERROR(r->Open(path));
  *reader = std::move(r);
  return Status::Ok();
}

}  // namespace

std::vector<std::string> SensorTypes::Lidar() const {
  std::vector<std::string> types = {point_cloud2};
  types.insert(types.end(), livox.begin(), livox.end());
  return types;
}

SensorTypes SensorTypesOf(const bag::MessageReader& reader) {
  const SensorTypes ros1_types = {ros1::kImuType, ros1::kPointCloud2Type,
                                  {ros1::kLivoxCustomMsgType, ros1::kLivox2CustomMsgType}};
  const SensorTypes ros2_types = {
      ros2::kImuType,
      ros2::kPointCloud2Type,
      {ros2::kLivox2CustomMsgType, ros2::kLivoxInterfacesCustomMsgType}};
  // A ROS 1 bag, or an MCAP with the ROS 1 type names, is read as ROS 1.
  for (const bag::TopicInfo& t : reader.topics()) {
    for (const std::string& type : ros1_types.Lidar()) {
      if (t.type == ros1::kImuType || t.type == type) return ros1_types;
    }
  }
  if (reader.format_name() == "ROS 1 bag") return ros1_types;
  return ros2_types;
}

Status OpenBagInput(const std::string& path, size_t chunk_cache_size,
                    std::unique_ptr<bag::MessageReader>* reader) {
  std::error_code ec;
  const fs::path p(path);
  if (fs::is_directory(p, ec)) {
    const fs::path metadata = p / "metadata.yaml";
    if (!fs::exists(metadata, ec)) {
      return Status::Error(path + ": a folder without metadata.yaml; expected " + kShapes);
    }
    std::string storage, first_file;
    ReadStorage(metadata.string(), &storage, &first_file);
    if (storage == "mcap") {
      if (first_file.empty()) return Status::Error(metadata.string() + ": no relative_file_paths");
      return OpenWith(std::make_unique<mcap::McapReader>(),
                      (p / fs::path(first_file).filename()).string(), reader);
    }
    if (!storage.empty() && storage != "sqlite3") {
      return Status::Error(metadata.string() + ": storage_identifier '" + storage +
                           "' (known: sqlite3, mcap)");
    }
    return OpenWith(std::make_unique<ros2::SqliteBagReader>(), path, reader);
  }
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
  return OpenWith(std::make_unique<Ros1MessageReader>(chunk_cache_size), path, reader);
}

}  // namespace tiltcal::decode
