#ifndef TILTCAL_BAG_ROS2_ROSBAG2_METADATA_H_
#define TILTCAL_BAG_ROS2_ROSBAG2_METADATA_H_

// The keys of a rosbag2 metadata.yaml the readers need (sqlite3 and MCAP
// storage alike), parsed from its text without a YAML library:
//   storage_identifier:    "sqlite3", "mcap" ("" when absent);
//   relative_file_paths:   a block list ("- a_0.db3" lines below the key)
//                          or a flow list ("[a_0.db3, a_1.db3]"), entries
//                          optionally quoted;
//   compression_format:    "" for an uncompressed bag.
// Values may be quoted ('x' or "x"). Every other key is ignored.
// ParseRosbag2Metadata does no I/O; ReadRosbag2Metadata reads the file,
// which must be a regular file of at most kMaxRosbag2MetadataBytes.

#include <cstddef>
#include <string>
#include <vector>

#include "common/status.h"

namespace tiltcal::ros2 {

struct Rosbag2Metadata {
  std::string storage_identifier;
  std::vector<std::string> relative_file_paths;
  std::string compression_format;
};

Rosbag2Metadata ParseRosbag2Metadata(const std::string& text);

// rosbag2 writes a few KB per topic; a larger file is not a metadata.yaml.
inline constexpr size_t kMaxRosbag2MetadataBytes = size_t{4} << 20;

// Reads and parses the metadata.yaml at `file`. A FIFO, a device, a file
// larger than kMaxRosbag2MetadataBytes are errors naming it, before it is
// read.
Status ReadRosbag2Metadata(const std::string& file, Rosbag2Metadata* metadata);

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_ROSBAG2_METADATA_H_
