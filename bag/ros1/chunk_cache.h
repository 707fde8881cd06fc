#ifndef TILTCAL_BAG_ROS1_CHUNK_CACHE_H_
#define TILTCAL_BAG_ROS1_CHUNK_CACHE_H_

// The decompressed chunks of a bag as BagReader::ReadMessages() uses them: a
// small LRU cache of decompressed chunks, and an optional read-ahead that
// reads and decompresses the next chunks on a second thread while the
// messages of the current one are handed out.

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "bag/ros1/bag_index.h"
#include "bag/ros1/bag_reader.h"
#include "bag/ros1/chunk_codec.h"
#include "bag/ros1/record_file.h"
#include "common/status.h"

namespace tiltcal::ros1 {

// A growable byte buffer that does not zero-fill.
class ByteBuffer {
 public:
  // Grows to size + size / 8 rounded up to 64 KiB, so that chunks of
  // varying size reuse the buffers instead of mapping and faulting in new
  // ones each time a chunk is a little larger than the last.
  uint8_t* Reserve(size_t size);
  uint8_t* data() { return data_.get(); }
  void Swap(ByteBuffer* other);

 private:
  std::unique_ptr<uint8_t[]> data_;
  size_t capacity_ = 0;
};

// Reads `chunk` from `file` and decompresses it with `decompressor` into
// `dst` (chunk.size bytes); *compressed holds the bytes read. Reads the file
// with pread only: safe on another thread with its own decompressor.
Status LoadChunk(const RecordFile& file, const Chunk& chunk, ChunkDecompressor* decompressor,
                 std::vector<uint8_t>* compressed, uint8_t* dst);
// Counts one load of `chunk` in *stats.
void CountChunkLoad(const Chunk& chunk, ReaderStats* stats);

// Reads and decompresses chunks on its own thread, in a fixed order (the
// order in which ReadMessages first needs them), at most `depth` ahead of the
// one taken last. Each load is the same LoadChunk, with its own decompressor
// and compressed-bytes buffer.
class ChunkReadAhead {
 public:
  ChunkReadAhead(const RecordFile& file, const std::vector<Chunk>& chunks,
                 std::vector<uint32_t> order, size_t depth);
  ~ChunkReadAhead();
  ChunkReadAhead(const ChunkReadAhead&) = delete;
  ChunkReadAhead& operator=(const ChunkReadAhead&) = delete;

  // When `chunk` is the next chunk of the order, waits until it is loaded,
  // swaps its bytes into *buffer (the old bytes of *buffer are reused for a
  // later chunk), sets *status to the load's result and returns true. Any
  // other chunk (one needed again after the cache evicted it): false.
  bool Take(uint32_t chunk, ByteBuffer* buffer, Status* status);

 private:
  struct Loaded {
    ByteBuffer buffer;
    Status status;
  };

  void Work();

  const RecordFile& file_;
  const std::vector<Chunk>& chunks_;
  const std::vector<uint32_t> order_;
  const size_t depth_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Loaded> ready_;   // loaded chunks order_[next_take_], ... in order
  std::vector<ByteBuffer> spare_;
  size_t next_take_ = 0;
  bool stopping_ = false;
  std::thread thread_;
};

// LRU cache of decompressed chunks, keyed by chunk index. A miss takes the
// chunk from the read-ahead (when there is one and the chunk is its next) or
// loads it on the calling thread with `decompressor`; either load is counted
// in *stats.
class ChunkCache {
 public:
  ChunkCache(const RecordFile& file, const std::vector<Chunk>& chunks,
             ChunkDecompressor* decompressor, ReaderStats* stats, size_t capacity,
             ChunkReadAhead* read_ahead);

  // The decompressed bytes of chunk `chunk`, loading it on a miss.
  Status Get(uint32_t chunk, const uint8_t** data);

 private:
  struct Slot {
    int64_t chunk = -1;
    uint64_t last_use = 0;
    ByteBuffer buffer;
  };
  const RecordFile& file_;
  const std::vector<Chunk>& chunks_;
  ChunkDecompressor* decompressor_;
  ReaderStats* stats_;
  std::vector<Slot> slots_;
  ChunkReadAhead* read_ahead_;
  std::vector<uint8_t> compressed_;
  uint64_t clock_ = 0;
};

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_CHUNK_CACHE_H_
