#include "bag/message_reader.h"

namespace tiltcal::bag {

std::string DescribePosition(const Message& m) {
  std::string out = std::string(m.position_name) + " " + std::to_string(m.position);
  if (m.file != nullptr) out += " in " + *m.file;
  return out;
}

std::vector<std::string> MessageReader::TopicNames() const {
  std::vector<std::string> names;
  for (const TopicInfo& t : topics()) names.push_back(t.name);
  return names;
}

std::vector<std::string> MessageReader::TopicsOfType(const std::string& type) const {
  std::vector<std::string> names;
  for (const TopicInfo& t : topics()) {
    if (t.type == type) names.push_back(t.name);
  }
  return names;
}

std::string MessageReader::TopicType(const std::string& topic) const {
  for (const TopicInfo& t : topics()) {
    if (t.name == topic) return t.type;
  }
  return "";
}

int64_t MessageReader::MessageCount(const std::string& topic) const {
  for (const TopicInfo& t : topics()) {
    if (t.name == topic) return t.message_count;
  }
  return 0;
}

int64_t MessageReader::TotalMessageCount() const {
  int64_t total = 0;
  for (const TopicInfo& t : topics()) total += t.message_count;
  return total;
}

}  // namespace tiltcal::bag
