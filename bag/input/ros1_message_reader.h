#ifndef TILTCAL_BAG_INPUT_ROS1_MESSAGE_READER_H_
#define TILTCAL_BAG_INPUT_ROS1_MESSAGE_READER_H_

// The ROS 1 bag reader (bag/ros1/bag_reader.h) behind the format-neutral
// MessageReader, so every format is read through one interface.
// Messages keep the reader's order and positions ("chunk at byte N").

#include <string>
#include <vector>

#include "bag/message_reader.h"
#include "bag/ros1/bag_reader.h"

namespace tiltcal::bag {

class Ros1MessageReader : public MessageReader {
 public:
  // `chunk_cache_size`: decompressed chunks kept in memory;
  // `read_ahead_chunks`: chunks decompressed ahead on a second thread.
  Ros1MessageReader(size_t chunk_cache_size, size_t read_ahead_chunks)
      : chunk_cache_size_(chunk_cache_size), read_ahead_chunks_(read_ahead_chunks) {}

  Status Open(const std::string& path);

  const std::string& path() const override { return reader_.path(); }
  uint64_t size_bytes() const override { return reader_.file_size(); }
  std::string format_name() const override { return "ROS 1 bag"; }
  bool indexed() const override { return reader_.indexed(); }
  int64_t num_salvaged_messages() const override { return reader_.num_salvaged_messages(); }
  std::string salvage_note() const override { return reader_.salvage_note(); }
  uint64_t chunks_decompressed() const override { return reader_.stats().chunks_decompressed; }
  Status ChunkCompressions(std::map<std::string, int64_t>* compressions) const override {
    *compressions = reader_.ChunkCompressions();
    return Status::Ok();
  }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  bool TimeRange(int64_t* start_ns, int64_t* end_ns) const override {
    return reader_.TimeRange(start_ns, end_ns);
  }
  Status ReadMessages(const MessageSelection& selection,
                      const std::function<Status(const Message&)>& fn) override;

 private:
  size_t chunk_cache_size_;
  size_t read_ahead_chunks_;
  ros1::BagReader reader_;
  std::vector<TopicInfo> topics_;
};

}  // namespace tiltcal::bag

#endif  // TILTCAL_BAG_INPUT_ROS1_MESSAGE_READER_H_
