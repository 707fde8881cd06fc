#include "bag/input/ros1_message_reader.h"

namespace tiltcal::bag {

namespace {
constexpr char kChunkPosition[] = "chunk at byte";
}  // namespace

Status Ros1MessageReader::Open(const std::string& path) {
  TILTCAL_RETURN_IF_ERROR(reader_.Open(path));
  topics_.clear();
  for (const std::string& topic : reader_.Topics()) {
    topics_.push_back({topic, reader_.TopicType(topic), reader_.MessageCount(topic)});
  }
  return Status::Ok();
}

Status Ros1MessageReader::ReadMessages(const MessageSelection& selection,
                                       const std::function<Status(const Message&)>& fn) {
  ros1::ReadOptions options;
  options.topics = selection.topics;
  options.start_ns = selection.start_ns;
  options.end_ns = selection.end_ns;
  options.chunk_cache_size = chunk_cache_size_;
  options.read_ahead_chunks = read_ahead_chunks_;
  Message m;
  m.encoding = Encoding::kRos1;
  m.file = nullptr;  // the one file: the path decode names first
  m.position_name = kChunkPosition;
  return reader_.ReadMessages(options, [&](const ros1::MessageView& v) {
    m.topic = &v.connection->topic;
    m.time_ns = v.time_ns;
    m.sequence = v.sequence;
    m.position = v.chunk_pos;
    m.data = v.data;
    m.size = v.size;
    return fn(m);
  });
}

}  // namespace tiltcal::bag
