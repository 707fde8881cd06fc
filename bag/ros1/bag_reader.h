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
//
// The parts: record_file.h (records at byte offsets), bag_index.h (what the
// index says), bag_salvage.h (the scan of an unindexed bag), chunk_cache.h
// (the LRU cache of decompressed chunks and the read-ahead).

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bag/ros1/bag_index.h"
#include "bag/ros1/chunk_codec.h"
#include "bag/ros1/format.h"
#include "bag/ros1/record_file.h"
#include "common/status.h"

namespace tiltcal::ros1 {

class ChunkReadAhead;

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

  const std::string& path() const { return file_.path(); }
  uint64_t file_size() const { return file_.size(); }
  // False for a bag without index (index_pos 0), read by a linear scan.
  bool indexed() const { return indexed_; }
  // Messages recovered by the linear scan of an unindexed bag, and what
  // could not be recovered ("" when nothing was lost).
  int64_t num_salvaged_messages() const { return num_salvaged_; }
  const std::string& salvage_note() const { return salvage_note_; }

  const std::vector<Connection>& connections() const { return index_.connections; }
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
  // One message to yield: its index entry and connection slot.
  struct Item {
    int64_t time_ns;
    uint32_t chunk;
    uint32_t offset;
    uint32_t slot;
  };

  // The version line: an error naming what the file is when it is not a
  // ROS1 bag of format 2.0.
  Status CheckVersionLine() const;
  Status ReadIndexed(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count);
  // The index section of an indexed bag: connection records from *pos (left
  // just past them), then the chunk info records, then each chunk's header.
  Status ReadConnectionRecords(uint32_t conn_count, uint64_t* pos);
  Status ReadChunkInfos(uint32_t chunk_count, uint64_t pos);
  Status ReadChunkHeaders();
  Status ReadChunkIndex(size_t chunk_index, const std::vector<size_t>& connection_slots);
  // Reads the index entries of the connection slots not read yet.
  Status LoadEntries(const std::vector<size_t>& slots);
  // The connection slots of the topics of `options`; an error for a topic
  // that is not in the bag.
  Status SelectSlots(const ReadOptions& options, std::vector<size_t>* slots) const;
  // The read-ahead of the chunks of `items` (nullptr for depth 0 or fewer
  // than two chunks).
  std::unique_ptr<ChunkReadAhead> StartReadAhead(const std::vector<Item>& items,
                                                 size_t depth) const;
  // The message record at *offset of `buffer` (the decompressed `chunk`),
  // past any connection records before it (*offset is moved to it).
  Status FindMessageRecord(const Chunk& chunk, const uint8_t* buffer, size_t* offset,
                           BufferRecord* record) const;
  // The entries of `slots` inside the time window of `options`, ordered by
  // (time, chunk_pos, offset).
  std::vector<Item> MergedItems(const std::vector<size_t>& slots,
                                const ReadOptions& options) const;

  RecordFile file_;
  bool indexed_ = true;
  int64_t num_salvaged_ = 0;
  std::string salvage_note_;
  BagIndex index_;
  ChunkDecompressor decompressor_;
  ReaderStats stats_;
};

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_BAG_READER_H_
