#ifndef TILTCAL_BAG_MESSAGE_READER_H_
#define TILTCAL_BAG_MESSAGE_READER_H_

// What every bag reader offers the decode stage, whatever the format (ROS 1
// bag, rosbag2 sqlite3, MCAP): the topics with their types and message
// counts, the record-time range, and the messages of chosen topics inside a
// record-time window, in record-time order, one at a time (memory does not
// grow with the bag). The messages stay serialized; `encoding` says how
// (bag/ros1/messages.h or bag/ros2/messages.h decodes them).

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "common/status.h"

namespace tiltcal::bag {

// The most bytes one decompressed chunk of any format may hold, unless the
// caller sets its own limit (decode params max_decompressed_chunk_mib).
inline constexpr uint64_t kDefaultMaxChunkBytes = uint64_t{256} << 20;

// How the messages are serialized.
enum class Encoding { kRos1, kCdr };

struct TopicInfo {
  std::string name;
  std::string type;  // "sensor_msgs/Imu" (ROS 1), "sensor_msgs/msg/Imu" (ROS 2)
  int64_t message_count = 0;
};

// One message, valid only during the callback that receives it.
struct Message {
  const std::string* topic = nullptr;
  Encoding encoding = Encoding::kRos1;
  int64_t time_ns = 0;    // record (receive) time, ns since the epoch
  uint64_t sequence = 0;  // 0-based position in this ReadMessages() call
  // Where the message is, for error messages: "<position_name> <position>
  // in <file>", e.g. "chunk at byte 4096 in a.bag", "row 17 in a_0.db3".
  const std::string* file = nullptr;
  const char* position_name = "";
  uint64_t position = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

// "chunk at byte 4096 in a.bag".
std::string DescribePosition(const Message& m);

struct MessageSelection {
  std::vector<std::string> topics;  // empty = every topic
  int64_t start_ns = INT64_MIN;     // record-time window [start_ns, end_ns)
  int64_t end_ns = INT64_MAX;
};

class MessageReader {
 public:
  virtual ~MessageReader() = default;

  // The path given to the reader (a file or a folder).
  virtual const std::string& path() const = 0;
  // Every file the reader reads, in its order (a single file: path()).
  virtual std::vector<std::string> input_files() const { return {path()}; }
  // Bytes of every file read.
  virtual uint64_t size_bytes() const = 0;
  // The format, for the log: "ROS 1 bag", "rosbag2 sqlite3", "MCAP".
  virtual std::string format_name() const = 0;
  // False when the reader had no index and scanned the file(s), salvaging
  // what it could; salvage_note() then says what was lost ("" if nothing).
  virtual bool indexed() const = 0;
  virtual int64_t num_salvaged_messages() const { return 0; }
  virtual std::string salvage_note() const { return ""; }
  // What the reader left out of what the files hold, and why, one line each
  // naming the file and with counts (a damaged record skipped, rows without
  // a usable record time, files of the folder not read, a summary that
  // disagrees with the data). Empty when everything was read. Known after
  // Open(); decode prints them as warnings and keeps them in the provenance.
  virtual std::vector<std::string> warnings() const { return {}; }
  // Compressed chunks decompressed so far.
  virtual uint64_t chunks_decompressed() const { return 0; }
  // The chunks of the file(s) by compression ("none", "bz2", "lz4",
  // "zstd"); empty for a format without chunks (rosbag2 sqlite3).
  virtual Status ChunkCompressions(std::map<std::string, int64_t>* compressions) const {
    compressions->clear();
    return Status::Ok();
  }
  // Messages left out because another file of the sequence held the same
  // message (bag/merged_message_reader.h), in the last ReadMessages().
  virtual int64_t duplicates_dropped() const { return 0; }

  // Sorted by name.
  virtual const std::vector<TopicInfo>& topics() const = 0;
  // Record time of the earliest / latest message; false when there is none.
  virtual bool TimeRange(int64_t* start_ns, int64_t* end_ns) const = 0;

  // Calls `fn` for every selected message in record-time order (ties in the
  // order of the file(s)). Stops at the first error of `fn`.
  virtual Status ReadMessages(const MessageSelection& selection,
                              const std::function<Status(const Message&)>& fn) = 0;

  // Derived from topics().
  std::vector<std::string> TopicNames() const;
  std::vector<std::string> TopicsOfType(const std::string& type) const;
  std::string TopicType(const std::string& topic) const;  // "" when absent
  int64_t MessageCount(const std::string& topic) const;   // 0 when absent
  int64_t TotalMessageCount() const;
};

}  // namespace tiltcal::bag

#endif  // TILTCAL_BAG_MESSAGE_READER_H_
