#ifndef TILTCAL_BAG_ROS2_ROSBAG2_METADATA_FIGURES_H_
#define TILTCAL_BAG_ROS2_ROSBAG2_METADATA_FIGURES_H_

// What a rosbag2 metadata.yaml states about its bag (the recorder's own
// figures, which `tiltcal_inspect info` sets beside what the files hold),
// parsed from its text by indentation without a YAML library, in the layout
// rosbag2 writes:
//   rosbag2_bagfile_information:
//     storage_identifier: sqlite3
//     duration: {nanoseconds: N}          (block form)
//     starting_time: {nanoseconds_since_epoch: N}
//     message_count: N
//     topics_with_message_count:
//       - topic_metadata: {name, type, serialization_format, ...}
//         message_count: N
//     compression_format: ""
// Keys may be quoted; every other key is ignored. No I/O.

#include <cstdint>
#include <string>
#include <vector>

namespace tiltcal::ros2 {

struct Rosbag2TopicFigures {
  std::string name;
  std::string type;
  std::string serialization_format;
  int64_t message_count = -1;  // -1: not stated
};

struct Rosbag2Figures {
  int64_t version = -1;  // -1: not stated (so for every number below)
  std::string storage_identifier;
  std::string compression_format;
  std::string compression_mode;
  int64_t starting_time_ns = -1;
  int64_t duration_ns = -1;
  int64_t message_count = -1;
  std::vector<Rosbag2TopicFigures> topics;  // in the order of the file
  // Values that are not what their key needs ("message_count: x"), as
  // "key: value"; the figures then lack them.
  std::vector<std::string> unreadable;
};

Rosbag2Figures ParseRosbag2Figures(const std::string& text);

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_ROSBAG2_METADATA_FIGURES_H_
