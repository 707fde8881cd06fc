#ifndef TILTCAL_BAG_INPUT_BAG_INPUT_H_
#define TILTCAL_BAG_INPUT_BAG_INPUT_H_

// The input of tiltcal_decode and tiltcal_inspect, chosen by its shape:
//   a file starting with the MCAP magic      MCAP (bag/mcap/), ROS 2 cdr or ROS 1
//   a file starting with "SQLite format 3"   one rosbag2 sqlite3 .db3 (bag/ros2/)
//   any other file                           ROS 1 bag (bag/ros1/), as before
//   a folder with metadata.yaml              a rosbag2 bag: its .db3 files
//                                            (storage sqlite3), or its .mcap
//                                            files (storage mcap)
//   a folder without metadata.yaml           one sequence in several files:
//                                            its .bag, .mcap and .db3 files
//                                            (each by its first bytes; not
//                                            its sub-folders), merged in
//                                            record time (bag/merged_message_reader.h)
// A folder with neither is an error naming it and the shapes. Every file is
// refused before it is read unless it is a regular file (common/io/input_file.h);
// in a folder without metadata.yaml, an entry named like a bag that is a
// dangling symbolic link, a symbolic link loop, a FIFO or a device is an
// error naming it (sub-folders are not read). A rosbag2 folder's
// metadata.yaml is read by one parser for both storages
// (bag/ros2/rosbag2_metadata.h): its files must exist, a compression_format
// is refused, and files of the storage's extension it does not list are
// named in a warning (MessageReader::warnings()).

#include <memory>
#include <string>
#include <vector>

#include "bag/message_reader.h"
#include "common/status.h"

namespace tiltcal::bag {

// The type names decode reads, in the naming of the input's format.
struct SensorTypes {
  const char* imu;
  const char* point_cloud2;
  std::vector<std::string> livox;  // the Livox CustomMsg types of the format
  std::vector<std::string> tf;     // the TFMessage types of /tf_static
  // The LiDAR types: point_cloud2, then the Livox types.
  std::vector<std::string> Lidar() const;
};
SensorTypes SensorTypesOf(const MessageReader& reader);

// How the ROS 1 reader holds its chunks (decode params chunk_cache_size and
// read_ahead_chunks).
struct Ros1ChunkSettings {
  size_t cache_size = 8;  // decompressed chunks kept
  size_t read_ahead = 0;  // chunks decompressed ahead on a second thread
};

// The most memory one decompressed MCAP chunk may take (decode params
// max_decompressed_chunk_mib); a chunk that declares more is an error.
struct ReaderLimits {
  uint64_t max_chunk_bytes = kDefaultMaxChunkBytes;
};

// Opens `path` with the reader of its shape.
Status OpenBagInput(const std::string& path, const Ros1ChunkSettings& ros1_chunks,
                    std::unique_ptr<MessageReader>* reader,
                    const ReaderLimits& limits = ReaderLimits());

// Opens the one file `path` by its first bytes (MCAP, sqlite3, else ROS 1).
Status OpenBagFile(const std::string& path, const Ros1ChunkSettings& ros1_chunks,
                   std::unique_ptr<MessageReader>* reader,
                   const ReaderLimits& limits = ReaderLimits());

}  // namespace tiltcal::bag

#endif  // TILTCAL_BAG_INPUT_BAG_INPUT_H_
