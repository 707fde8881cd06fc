#ifndef TILTCAL_BAG_ROS1_BAG_WRITER_H_
#define TILTCAL_BAG_ROS1_BAG_WRITER_H_

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "bag/ros1/chunk_codec.h"
#include "common/io/atomic_file.h"
#include "common/status.h"

namespace tiltcal::ros1 {

// Writes a ROS1 bag, format 2.0, as ros_comm's rosbag does
// (wiki.ros.org/Bags/Format/2.0; record primitives in bag/ros1/format.h):
//   version line · bag header (padded to 4096 bytes, rewritten on Close) ·
//   { chunk (connection records on first use + message data records),
//     compressed none / bz2 / lz4 (one LZ4 frame, 1 MiB independent blocks,
//     content checksum, as roslz4) · one index data record per connection } ·
//   connection records · chunk info records.
// A chunk is closed when its uncompressed size reaches the threshold. The
// output is written atomically: nothing is left at `path` unless Close()
// succeeds. The bytes depend only on the calls made (no clock, no host data).
class BagWriter {
 public:
  BagWriter() = default;
  BagWriter(const BagWriter&) = delete;
  BagWriter& operator=(const BagWriter&) = delete;

  // `compression_threads` chunks are compressed in parallel (bz2 is slow);
  // the bytes do not depend on it.
  Status Open(const std::string& path, ChunkCompression compression,
              uint32_t chunk_threshold_bytes, unsigned compression_threads = 1);
  // Registers a connection (topic, message type); returns its id.
  uint32_t AddConnection(const std::string& topic, const std::string& type,
                         const std::string& md5sum, const std::string& definition);
  // Appends one serialized message with record time `time_ns` (ns since epoch).
  Status Write(uint32_t connection, int64_t time_ns, std::string_view message);
  // Flushes the last chunk, writes the index section and the final bag header.
  Status Close();

  uint64_t bytes_written() const { return position_; }

 private:
  struct Connection {
    std::string topic;
    std::string type;
    std::string md5sum;
    std::string definition;
    bool written = false;  // its record has been put into a chunk
  };
  struct IndexEntry {
    int64_t time_ns;
    uint32_t offset;
  };
  struct PendingChunk {  // closed, not yet compressed and written
    std::string data;
    std::map<uint32_t, std::vector<IndexEntry>> index;
    int64_t start_ns, end_ns;
  };
  struct ChunkInfo {
    uint64_t position;
    int64_t start_ns, end_ns;
    std::map<uint32_t, uint32_t> counts;  // connection -> messages
  };

  Status WriteBytes(std::string_view bytes);
  Status FlushChunk();
  Status WritePendingChunks();
  std::string BagHeaderRecord(uint64_t index_position) const;
  std::string ConnectionRecord(uint32_t id) const;

  AtomicFile file_;
  std::string path_;
  ChunkCompression compression_ = ChunkCompression::kNone;
  uint32_t chunk_threshold_ = 768 * 1024;
  uint64_t position_ = 0;
  std::vector<Connection> connections_;
  std::string chunk_;  // uncompressed records of the open chunk
  std::map<uint32_t, std::vector<IndexEntry>> chunk_index_;
  int64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  std::vector<ChunkInfo> chunk_infos_;
  std::vector<PendingChunk> pending_;
  unsigned compression_threads_ = 1;
  bool open_ = false;
};

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_BAG_WRITER_H_
