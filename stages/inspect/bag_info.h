#ifndef TILTCAL_STAGES_INSPECT_BAG_INFO_H_
#define TILTCAL_STAGES_INSPECT_BAG_INFO_H_

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bag/ros2/rosbag2_metadata_figures.h"
#include "common/status.h"

namespace tiltcal::inspect {

// One topic as the files hold it. Times are record (receive) times, ns
// since the epoch.
struct TopicFigures {
  std::string name;
  std::string type;
  std::string encoding;        // "ros1" or "cdr"; "" without messages
  int64_t indexed_count = 0;   // the reader's count before reading (index, summary, rows)
  int64_t count = 0;           // messages read
  int64_t first_ns = 0;        // with count > 0
  int64_t last_ns = 0;
  // 1 / the median interval between consecutive record times, as `rosbag
  // info` computes it (0 with fewer than two messages or a zero median).
  double rate_hz = 0.0;
  // Messages of a type decode reads (sensor_msgs Imu and PointCloud2, the
  // Livox CustomMsg, TFMessage) are deserialised: `decoded` of them did,
  // `decode_error` names the first that did not. Messages of other types
  // are only counted (sensor_type false).
  bool sensor_type = false;
  int64_t decoded = 0;
  int64_t decode_failures = 0;
  std::string decode_error;
};

// What a bag holds: every input decode reads (bag/input/bag_input.h), read
// through the same code in one pass over every message.
struct BagInfo {
  std::string path;
  std::string format;  // the reader's name ("ROS 1 bag", "MCAP", "rosbag2 sqlite3", ...)
  std::vector<std::string> files;
  uint64_t size_bytes = 0;
  bool indexed = true;
  std::string salvage_note;                         // what a salvaging reader lost
  std::map<std::string, int64_t> chunk_compressions;  // chunks by compression
  int64_t duplicates_dropped = 0;  // a folder of overlapping files
  int64_t message_count = 0;
  int64_t first_ns = 0;  // with message_count > 0
  int64_t last_ns = 0;
  std::vector<TopicFigures> topics;  // sorted by name
  // A rosbag2 folder: what its metadata.yaml states.
  bool has_metadata = false;
  std::string metadata_path;
  ros2::Rosbag2Figures metadata;
  // Every disagreement (metadata.yaml against the files, the index against
  // the messages read, messages that do not deserialise, data lost).
  std::vector<std::string> warnings;
};

// Opens `path` and reads every message. Errors: a bag that cannot be
// opened or read (naming the file), a metadata.yaml that cannot be read.
Status ReadBagInfo(const std::string& path, BagInfo* info);

}  // namespace tiltcal::inspect

#endif  // TILTCAL_STAGES_INSPECT_BAG_INFO_H_
