#ifndef TILTCAL_BAG_ROS1_BAG_READER_H_
#define TILTCAL_BAG_ROS1_BAG_READER_H_

// Reader for ROS1 bags, format 2.0 (see format.h for the layout and
// ../shared/reference/bag-formats.md for the pitfalls), without ROS.
//
// Open() reads the bag header, the connection records and the chunk infos of
// an indexed bag (index_pos != 0), or scans an unindexed one (index_pos == 0,
// an interrupted recording) record by record, salvaging every complete
// message (including those of an open, uncompressed chunk).
// ReadMessages() yields the messages of chosen topics in record-time order
// (sorted by (time, chunk_pos, offset), so chunks may be out of time order),
// decompressing chunks on demand into a small LRU cache: memory is bounded by
// cache_size chunks plus 16 bytes per selected message, whatever the bag size.
// With read_ahead_chunks > 0 a second thread reads and decompresses the next
// chunks (in the order of their first use) while the messages of the current
// one are handed out, at most that many ahead.
// The file is read with pread(); nothing is memory-mapped.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
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

// One message as yielded by ReadMessages(). `data` points into the reader's
// chunk cache and stays valid only during the callback.
struct MessageView {
  const Connection* connection = nullptr;
  int64_t time_ns = 0;     // record (receive) time, ns since epoch
  uint64_t chunk_pos = 0;  // file offset of the chunk record holding it
  uint32_t offset = 0;     // offset of its record in the uncompressed chunk
  uint64_t sequence = 0;   // 0-based position in this ReadMessages() call
  const uint8_t* data = nullptr;  // serialized message (ROS1 wire format)
  size_t size = 0;
};

struct ReadOptions {
  // Topics to read; empty = every topic.
  std::vector<std::string> topics;
  // Record-time window [start_ns, end_ns).
  int64_t start_ns = INT64_MIN;
  int64_t end_ns = INT64_MAX;
  // Decompressed chunks kept in memory.
  size_t chunk_cache_size = 8;
  // Chunks read and decompressed ahead on a second thread (0: none, every
  // chunk is loaded on the calling thread when first needed).
  size_t read_ahead_chunks = 0;
};

// Counters of a reader, for summaries and tests.
struct ReaderStats {
  uint64_t chunks_decompressed = 0;     // including re-decompressions after eviction
  uint64_t compressed_bytes_read = 0;   // chunk data bytes read from the file
  uint64_t uncompressed_bytes = 0;      // bytes produced by decompression
};

class BagReader {
 public:
  BagReader();
  ~BagReader();
  BagReader(const BagReader&) = delete;
  BagReader& operator=(const BagReader&) = delete;

  // Opens `path` and reads its index (or scans it). Every error names the
  // file and, where it applies, the byte offset of the record at fault.
  Status Open(const std::string& path);

  const std::string& path() const { return path_; }
  uint64_t file_size() const { return file_size_; }
  // False for a bag without index (index_pos 0), read by a linear scan.
  bool indexed() const { return indexed_; }
  // Messages recovered by the linear scan of an unindexed bag, and what
  // could not be recovered ("" when nothing was lost).
  int64_t num_salvaged_messages() const { return num_salvaged_; }
  const std::string& salvage_note() const { return salvage_note_; }

  const std::vector<Connection>& connections() const { return connections_; }
  // Topic names (sorted, unique) of connections whose type is `type`.
  std::vector<std::string> TopicsOfType(const std::string& type) const;
  // Sorted, unique topic names.
  std::vector<std::string> Topics() const;
  // Type of `topic` ("" when absent; the first connection's type).
  std::string TopicType(const std::string& topic) const;
  // Messages on `topic` (all connections), from the index.
  int64_t MessageCount(const std::string& topic) const;
  int64_t TotalMessageCount() const;
  // Record time of the earliest / latest message of the bag, ns; false when
  // the bag has no messages.
  bool TimeRange(int64_t* start_ns, int64_t* end_ns) const;

  // Calls `fn` for every message of the selected topics inside the window,
  // in (time, chunk_pos, offset) order. Stops at the first error of `fn`.
  Status ReadMessages(const ReadOptions& options,
                      const std::function<Status(const MessageView&)>& fn);

  const ReaderStats& stats() const { return stats_; }
  // The chunks by compression ("none", "bz2", "lz4").
  std::map<std::string, int64_t> ChunkCompressions() const;

 private:
  struct Chunk;
  struct Entry;
  class ChunkCache;
  // One message to yield: its index entry and connection slot.
  struct Item {
    int64_t time_ns;
    uint32_t chunk;
    uint32_t offset;
    uint32_t slot;
  };

  Status Error(uint64_t pos, const std::string& what) const;
  Status ReadAt(uint64_t pos, size_t size, void* dst) const;
  // Reads the record header at `pos`: header fields into *header (views into
  // *buffer), the data position and length. The record must fit in the file.
  Status ReadRecordHeaderAt(uint64_t pos, std::string* buffer, RecordHeader* header,
                            uint64_t* data_pos, uint32_t* data_len) const;
  Status ReadIndexed(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count);
  // The index section of an indexed bag: connection records from *pos (left
  // just past them), then the chunk info records, then each chunk's header.
  Status ReadConnectionRecords(uint32_t conn_count, uint64_t* pos);
  Status ReadChunkInfos(uint32_t chunk_count, uint64_t pos);
  Status ReadChunkHeaders();
  Status ReadChunkIndex(size_t chunk_index, const std::vector<size_t>& connection_slots);
  // Reads the index entries of the connection slots not read yet.
  Status LoadEntries(const std::vector<size_t>& slots);
  // The entries of `slots` inside the time window of `options`, ordered by
  // (time, chunk_pos, offset).
  std::vector<Item> MergedItems(const std::vector<size_t>& slots,
                                const ReadOptions& options) const;
  Status ScanUnindexed(uint64_t first_record_pos);
  // The compression and size fields of a chunk record header; the size must
  // be one its chunk->data_len bytes can hold (checked before allocating).
  static Status ParseChunkHeader(const RecordHeader& header, Chunk* chunk);
  // Scan of an unindexed bag: reads the chunk record at `pos` and indexes its
  // records; sets *stop (with salvage_note_ saying why) when nothing after
  // it can be trusted. Errors only for I/O failures.
  Status SalvageChunk(uint64_t pos, const RecordHeader& header, uint64_t data_pos,
                      uint32_t data_len, bool* stop);
  // A chunk still open when the recording stopped (size and data length 0):
  // its records run to the end of the file, up to the first incomplete one.
  Status SalvageOpenChunk(uint32_t chunk_index);
  // The one dispatch of the records inside a chunk (`size` uncompressed bytes
  // of chunk `chunk_index`): connection records add their connection, message
  // data records an index entry. Another op is skipped, or ends the records
  // of an `open` chunk (one whose size was never written). *end is the offset
  // just past the last record taken.
  Status IndexChunkRecords(const uint8_t* records, size_t size, uint32_t chunk_index, bool open,
                           size_t* end);
  void AddSalvagedEntry(uint32_t conn, RosTime time, uint32_t chunk, uint32_t offset);
  Status AddConnection(const RecordHeader& header, const uint8_t* data, size_t size,
                       uint64_t pos);
  class ChunkReadAhead;
  // Loads chunk `chunk_index` decompressed into `dst` (sized to the chunk size).
  Status LoadChunk(size_t chunk_index, std::vector<uint8_t>* compressed, uint8_t* dst);
  // LoadChunk with a decompressor of the caller, without counting it in the
  // stats (safe on another thread: reads the file with pread only).
  Status LoadChunkWith(size_t chunk_index, ChunkDecompressor* decompressor,
                       std::vector<uint8_t>* compressed, uint8_t* dst) const;
  void CountChunkLoad(size_t chunk_index);
  int ConnectionSlot(uint32_t id) const;

  std::string path_;
  int fd_ = -1;
  uint64_t file_size_ = 0;
  bool indexed_ = true;
  int64_t num_salvaged_ = 0;
  std::string salvage_note_;
  std::vector<Connection> connections_;
  std::vector<Chunk> chunks_;
  // Per connection slot: message count, and (once read) its index entries.
  std::vector<int64_t> message_counts_;
  std::vector<std::vector<Entry>> entries_;
  std::vector<bool> entries_loaded_;
  int64_t start_ns_ = INT64_MAX;
  int64_t end_ns_ = INT64_MIN;
  ChunkDecompressor decompressor_;
  ReaderStats stats_;
};

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_BAG_READER_H_
