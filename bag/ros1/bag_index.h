#ifndef TILTCAL_BAG_ROS1_BAG_INDEX_H_
#define TILTCAL_BAG_ROS1_BAG_INDEX_H_

// What a BagReader knows of a bag before it reads a message: the connections,
// the chunk records and, per connection, where each message is. Read from the
// index section of an indexed bag, or rebuilt by the scan of an unindexed one
// (bag_salvage.h).

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bag/ros1/chunk_codec.h"
#include "bag/ros1/format.h"
#include "common/status.h"

namespace tiltcal::ros1 {

// A connection (one publisher of one topic). Several may share a topic.
struct Connection {
  uint32_t id = 0;
  std::string topic;  // from the outer record header, always present
  std::string type;   // e.g. "sensor_msgs/Imu"
  std::string md5sum;
  std::string message_definition;
  std::string callerid;  // empty when not recorded
};

// A chunk record: where its data is and how to decompress it.
struct Chunk {
  uint64_t pos = 0;        // file offset of the chunk record
  uint64_t data_pos = 0;   // file offset of its (compressed) data
  uint32_t data_len = 0;   // compressed bytes
  uint32_t size = 0;       // uncompressed bytes
  ChunkCompression compression = ChunkCompression::kNone;
  uint64_t index_pos = 0;  // first index data record after the chunk (indexed bags)
  // (connection slot, message count) from the chunk info record.
  std::vector<std::pair<int, uint32_t>> connection_counts;
};

// Reads the fields of a chunk record header: compression and uncompressed
// size. The size is checked against the chunk's data bytes (chunk->data_len,
// which fit in the file) before anything is allocated for it.
Status ParseChunkHeader(const RecordHeader& header, Chunk* chunk);

// Where one message record is: 16 bytes per message.
struct IndexEntry {
  int64_t time_ns;
  uint32_t chunk;   // index into BagIndex::chunks (sorted by file position)
  uint32_t offset;  // record offset in the uncompressed chunk
};

struct BagIndex {
  std::vector<Connection> connections;
  std::vector<Chunk> chunks;
  // Per connection slot (index into `connections`): message count, and (once
  // read) its index entries.
  std::vector<int64_t> message_counts;
  std::vector<std::vector<IndexEntry>> entries;
  std::vector<bool> entries_loaded;
  // Record time of the earliest / latest message; start_ns > end_ns without
  // messages.
  int64_t start_ns = INT64_MAX;
  int64_t end_ns = INT64_MIN;

  // The slot of connection `id`, -1 when unknown.
  int ConnectionSlot(uint32_t id) const;
  // Adds the connection of a connection record (outer header `header`,
  // `size` bytes of inner header block at `data`) unless its id is known.
  // `entries_loaded`: its index entries are all known (a scanned bag) rather
  // than still to be read from the index. Errors start "connection record: ".
  Status AddConnection(const RecordHeader& header, const uint8_t* data, size_t size,
                       bool entries_loaded);
};

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_BAG_INDEX_H_
