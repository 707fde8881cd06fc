#ifndef TILTCAL_BAG_MERGED_MESSAGE_READER_H_
#define TILTCAL_BAG_MERGED_MESSAGE_READER_H_

// One sequence recorded in several bag files (a ROS 1 recording split by
// time or size, the IMU and the LiDAR in separate bags, a rosbag2 MCAP bag
// split into several .mcap files), read as one bag: the topics of all files
// (matched by name; a type that differs between files is an error naming
// both), and their messages merged into one stream in record-time order.
//
// The merge is a k-way merge over the files' own ordered streams, key
// (record time, file index): ties keep the order of the files, and within a
// file its reader's order. Each file is read ahead on its own thread into a
// bounded queue (kMaxQueuedBytes / kMaxQueuedMessages, at least one
// message), started only when the merge reaches the file's first record
// time, so a time-split recording has one or two files open for reading at
// a time and memory does not grow with the number of files.
//
// Duplicates: a message with the same topic, the same record time and the
// same bytes as a message already given from another file (split files
// that overlap) is given once, from the first file, and counted
// (duplicates_dropped()). Messages that differ in any byte are all given.
//
// Files whose type names are ROS 1 ("sensor_msgs/Imu") and files whose
// names are ROS 2 ("sensor_msgs/msg/Imu") are not merged: an error names
// the first file of each that holds messages (files without messages are
// of neither version).

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "bag/message_reader.h"
#include "common/status.h"

namespace tiltcal::bag {

class MergedMessageReader : public MessageReader {
 public:
  // Bytes and messages one file may have read ahead of the merge.
  static constexpr size_t kMaxQueuedBytes = size_t{4} << 20;
  static constexpr size_t kMaxQueuedMessages = 1024;

  MergedMessageReader();
  ~MergedMessageReader() override;
  MergedMessageReader(const MergedMessageReader&) = delete;
  MergedMessageReader& operator=(const MergedMessageReader&) = delete;

  // `path`: what the user named (the folder); `files`: the opened readers,
  // in file-name order (the order of ties).
  Status Open(const std::string& path, std::vector<std::unique_ptr<MessageReader>> files);

  const std::string& path() const override { return path_; }
  std::vector<std::string> input_files() const override;
  uint64_t size_bytes() const override;
  std::string format_name() const override;
  bool indexed() const override;
  int64_t num_salvaged_messages() const override;
  std::string salvage_note() const override;
  std::vector<std::string> warnings() const override;  // every file's
  uint64_t chunks_decompressed() const override;
  Status ChunkCompressions(std::map<std::string, int64_t>* compressions) const override;
  int64_t duplicates_dropped() const override { return duplicates_dropped_; }
  const std::vector<TopicInfo>& topics() const override { return topics_; }
  bool TimeRange(int64_t* start_ns, int64_t* end_ns) const override;
  Status ReadMessages(const MessageSelection& selection,
                      const std::function<Status(const Message&)>& fn) override;

 private:
  class Source;
  struct Head;
  // The files that hold a selected topic inside the time window.
  std::vector<Head> OpenHeads(
      const MessageSelection& selection,
      const std::unordered_map<std::string, const std::string*>* topic_names) const;

  std::string path_;
  std::vector<std::unique_ptr<MessageReader>> files_;
  std::vector<TopicInfo> topics_;
  int64_t duplicates_dropped_ = 0;
};

}  // namespace tiltcal::bag

#endif  // TILTCAL_BAG_MERGED_MESSAGE_READER_H_
