#ifndef TILTCAL_BAG_ROS2_ROSBAG2_METADATA_H_
#define TILTCAL_BAG_ROS2_ROSBAG2_METADATA_H_

// The two keys of a rosbag2 metadata.yaml the sqlite3 reader needs, parsed
// from its text without a YAML library:
//   relative_file_paths:   a block list ("- a_0.db3" lines below the key)
//                          or a flow list ("[a_0.db3, a_1.db3]"), entries
//                          optionally quoted;
//   compression_format:    "" for an uncompressed bag.
// Every other key is ignored. No I/O.

#include <string>
#include <vector>

namespace tiltcal::ros2 {

struct Rosbag2Metadata {
  std::vector<std::string> relative_file_paths;
  std::string compression_format;
};

Rosbag2Metadata ParseRosbag2Metadata(const std::string& text);

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_ROSBAG2_METADATA_H_
