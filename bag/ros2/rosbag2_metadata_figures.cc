#include "bag/ros2/rosbag2_metadata_figures.h"

#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <utility>

#include "bag/ros2/yaml_scalar.h"

namespace tiltcal::ros2 {
namespace {

constexpr char kRootKey[] = "rosbag2_bagfile_information";

// The key of "key: value" (unquoted), its value (unquoted) and whether it
// opens a block (nothing after the colon); false when the line is no
// mapping entry.
bool SplitEntry(const std::string& t, std::string* key, std::string* value, bool* block) {
  size_t colon = std::string::npos;
  if (!t.empty() && (t[0] == '"' || t[0] == '\'')) {
    const size_t close = t.find(t[0], 1);
    if (close == std::string::npos) return false;
    colon = t.find(':', close);
  } else {
    colon = t.find(':');
  }
  if (colon == std::string::npos || (colon + 1 < t.size() && t[colon + 1] != ' ')) return false;
  *key = UnquoteYamlScalar(TrimYamlSpace(t.substr(0, colon)));
  const std::string raw = TrimYamlSpace(t.substr(colon + 1));
  *block = raw.empty();
  *value = UnquoteYamlScalar(raw);
  return true;
}

bool ParseInt(const std::string& text, int64_t* v) {
  if (text.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const long long parsed = std::strtoll(text.c_str(), &end, 10);
  if (errno != 0 || *end != '\0') return false;
  *v = parsed;
  return true;
}

// Collects the figures from (path, value) entries, path without the root
// key ("topics_with_message_count.topic_metadata.name").
class FiguresBuilder {
 public:
  explicit FiguresBuilder(Rosbag2Figures* figures) : f_(figures) {}

  void StartItem(const std::string& list) {
    if (list == "topics_with_message_count") f_->topics.emplace_back();
  }

  void Add(const std::string& path, const std::string& value) {
    if (path == "version") return Int(path, value, &f_->version);
    if (path == "storage_identifier") return void(f_->storage_identifier = value);
    if (path == "compression_format") return void(f_->compression_format = value);
    if (path == "compression_mode") return void(f_->compression_mode = value);
    if (path == "starting_time.nanoseconds_since_epoch") {
      return Int(path, value, &f_->starting_time_ns);
    }
    if (path == "duration.nanoseconds") return Int(path, value, &f_->duration_ns);
    if (path == "message_count") return Int(path, value, &f_->message_count);
    constexpr char kTopics[] = "topics_with_message_count.";
    if (path.rfind(kTopics, 0) != 0 || f_->topics.empty()) return;
    Rosbag2TopicFigures& topic = f_->topics.back();
    const std::string field = path.substr(sizeof(kTopics) - 1);
    if (field == "topic_metadata.name") topic.name = value;
    if (field == "topic_metadata.type") topic.type = value;
    if (field == "topic_metadata.serialization_format") topic.serialization_format = value;
    if (field == "message_count") Int(path, value, &topic.message_count);
  }

 private:
  void Int(const std::string& path, const std::string& value, int64_t* v) {
    if (!ParseInt(value, v)) f_->unreadable.push_back(path + ": " + value);
  }

  Rosbag2Figures* f_;
};

}  // namespace

Rosbag2Figures ParseRosbag2Figures(const std::string& text) {
  Rosbag2Figures figures;
  FiguresBuilder builder(&figures);
  // The open blocks: (indent of the key, key).
  std::vector<std::pair<size_t, std::string>> blocks;
  // "a.b" of the open blocks below the root key.
  auto block_path = [&] {
    std::string path;
    for (const auto& [indent, name] : blocks) {
      if (path.empty() && name == kRootKey) continue;
      path += (path.empty() ? "" : ".") + name;
    }
    return path;
  };
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    size_t indent = line.find_first_not_of(' ');
    if (indent == std::string::npos) continue;
    std::string t = TrimYamlSpace(line.substr(indent));
    if (t.empty() || t[0] == '#') continue;
    if (t.rfind("- ", 0) == 0 || t == "-") {
      // A list item: it belongs to the innermost block above its dash; its
      // entries start after the dash.
      while (!blocks.empty() && blocks.back().first >= indent) blocks.pop_back();
      builder.StartItem(block_path());
      const std::string rest = t.size() > 1 ? t.substr(2) : "";
      indent += 2 + (rest.size() - TrimYamlSpace(rest).size());
      t = TrimYamlSpace(rest);
      if (t.empty()) continue;
    }
    std::string key, value;
    bool block = false;
    if (!SplitEntry(t, &key, &value, &block)) continue;
    while (!blocks.empty() && blocks.back().first >= indent) blocks.pop_back();
    if (block) {
      blocks.emplace_back(indent, key);
    } else {
      const std::string parent = block_path();
      builder.Add(parent.empty() ? key : parent + "." + key, value);
    }
  }
  return figures;
}

}  // namespace tiltcal::ros2
