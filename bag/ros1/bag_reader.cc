#include "bag/ros1/bag_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <mutex>
#include <new>
#include <set>
#include <thread>
#include <tuple>
#include <unordered_map>

#include "common/io/input_file.h"

namespace tiltcal::ros1 {

// A chunk record: where its data is and how to decompress it.
struct BagReader::Chunk {
  uint64_t pos = 0;        // file offset of the chunk record
  uint64_t data_pos = 0;   // file offset of its (compressed) data
  uint32_t data_len = 0;   // compressed bytes
  uint32_t size = 0;       // uncompressed bytes
  ChunkCompression compression = ChunkCompression::kNone;
  uint64_t index_pos = 0;  // first index data record after the chunk (indexed bags)
  // (connection slot, message count) from the chunk info record.
  std::vector<std::pair<int, uint32_t>> connection_counts;
};

// Where one message record is: 16 bytes per message.
struct BagReader::Entry {
  int64_t time_ns;
  uint32_t chunk;   // index into chunks_ (sorted by file position)
  uint32_t offset;  // record offset in the uncompressed chunk
};

namespace {

// Sanity limits that keep a corrupted length from allocating gigabytes. Real
// record headers are tens of bytes; real chunks ~1 MB (a chunk holds at least
// one message, so a few hundred MB for a huge message at most).
constexpr uint32_t kMaxHeaderBytes = 1 << 20;
constexpr uint32_t kMaxChunkBytes = 1u << 30;
constexpr uint32_t kLz4MaxRatio = 256;

// A growable byte buffer that does not zero-fill.
class ByteBuffer {
 public:
  // Grows to size + size / 8 rounded up to 64 KiB, so that chunks of
  // varying size reuse the buffers instead of mapping and faulting in new
  // ones each time a chunk is a little larger than the last.
  uint8_t* Reserve(size_t size) {
    if (size > capacity_) {
      constexpr size_t kGranule = size_t{1} << 16;
      const size_t grown = size + size / 8;
      capacity_ = std::max(size, (grown + kGranule - 1) / kGranule * kGranule);
      data_.reset(new uint8_t[capacity_]);
    }
    return data_.get();
  }
  uint8_t* data() { return data_.get(); }
  void Swap(ByteBuffer* other) {
    std::swap(data_, other->data_);
    std::swap(capacity_, other->capacity_);
  }

 private:
  std::unique_ptr<uint8_t[]> data_;
  size_t capacity_ = 0;
};

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

// The op of `header` must be `expected`; otherwise the error is "expected
// <what>, found op N (name)".
Status RequireOp(const RecordHeader& header, Op expected, const std::string& what) {
  uint8_t op = 0;
  TILTCAL_RETURN_IF_ERROR(header.GetOp(&op));
  if (op != static_cast<uint8_t>(expected)) {
    return Status::Error("expected " + what + ", found op " + std::to_string(op) + " (" +
                         OpName(op) + ")");
  }
  return Status::Ok();
}

}  // namespace

// Reads the fields of a chunk record header: compression and uncompressed
// size. The size is checked against the chunk's data bytes (chunk->data_len,
// which fit in the file) before anything is allocated for it: equal for an
// uncompressed chunk, at most 256 times for lz4 (an LZ4 sequence adds at
// most 255 bytes of match per length byte); bz2, whose runs compress far
// more, is held to the 1 GiB maximum only.
Status BagReader::ParseChunkHeader(const RecordHeader& header, Chunk* chunk) {
  std::string compression;
  TILTCAL_RETURN_IF_ERROR(header.GetString("compression", &compression));
  TILTCAL_RETURN_IF_ERROR(header.GetU32("size", &chunk->size));
  if (!ParseChunkCompression(compression, &chunk->compression)) {
    return Status::Error("unsupported chunk compression " + Quoted(compression) +
                         " (supported: none, bz2, lz4)");
  }
  if (chunk->size > kMaxChunkBytes) {
    return Status::Error("implausible uncompressed size " + std::to_string(chunk->size) +
                         " (> 1 GiB; corrupt bag?)");
  }
  if (chunk->compression == ChunkCompression::kNone && chunk->size != chunk->data_len) {
    return Status::Error("uncompressed chunk of size " + std::to_string(chunk->size) +
                         " has " + std::to_string(chunk->data_len) + " data bytes");
  }
  if (chunk->compression == ChunkCompression::kLz4 &&
      chunk->size / kLz4MaxRatio > chunk->data_len) {
    return Status::Error("lz4 chunk of " + std::to_string(chunk->data_len) +
                         " data bytes cannot decompress to the " + std::to_string(chunk->size) +
                         " bytes it declares (at most " + std::to_string(kLz4MaxRatio) +
                         " per byte; corrupt bag?)");
  }
  return Status::Ok();
}

// Reads and decompresses chunks on its own thread, in a fixed order (the
// order in which ReadMessages first needs them), at most `depth` ahead of the
// one taken last. Each load is the same LoadChunk, with its own decompressor
// and compressed-bytes buffer.
class BagReader::ChunkReadAhead {
 public:
  ChunkReadAhead(const BagReader* reader, std::vector<uint32_t> order, size_t depth)
      : reader_(reader), order_(std::move(order)), depth_(std::max<size_t>(depth, 1)) {
    thread_ = std::thread([this] { Work(); });
  }
  ~ChunkReadAhead() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  ChunkReadAhead(const ChunkReadAhead&) = delete;
  ChunkReadAhead& operator=(const ChunkReadAhead&) = delete;

  // When `chunk` is the next chunk of the order, waits until it is loaded,
  // swaps its bytes into *buffer (the old bytes of *buffer are reused for a
  // later chunk), sets *status to the load's result and returns true. Any
  // other chunk (one needed again after the cache evicted it): false.
  bool Take(uint32_t chunk, ByteBuffer* buffer, Status* status) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (next_take_ >= order_.size() || order_[next_take_] != chunk) return false;
    changed_.wait(lock, [this] { return !ready_.empty(); });
    Loaded& loaded = ready_.front();
    buffer->Swap(&loaded.buffer);
    *status = std::move(loaded.status);
    spare_.push_back(std::move(loaded.buffer));
    ready_.pop_front();
    ++next_take_;
    changed_.notify_all();
    return true;
  }

 private:
  struct Loaded {
    ByteBuffer buffer;
    Status status;
  };

  void Work() {
    ChunkDecompressor decompressor;
    std::vector<uint8_t> compressed;
    for (size_t next = 0; next < order_.size(); ++next) {
      ByteBuffer buffer;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        changed_.wait(lock, [this] { return stopping_ || ready_.size() < depth_; });
        if (stopping_) return;
        if (!spare_.empty()) {
          buffer.Swap(&spare_.back());
          spare_.pop_back();
        }
      }
      const uint32_t chunk = order_[next];
      Status status;
      try {  // an exception would end the process from this thread
        uint8_t* dst = buffer.Reserve(std::max<size_t>(reader_->chunks_[chunk].size, 1));
        status = reader_->LoadChunkWith(chunk, &decompressor, &compressed, dst);
      } catch (const std::bad_alloc&) {
        status = Status::Error(reader_->path_ + ": chunk at byte " +
                               std::to_string(reader_->chunks_[chunk].pos) +
                               ": out of memory decompressing it");
      }
      const bool failed = !status.ok();
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ready_.push_back(Loaded{std::move(buffer), std::move(status)});
      }
      changed_.notify_all();
      if (failed) return;  // the caller stops at this error
    }
  }

  const BagReader* reader_;
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

// LRU cache of decompressed chunks, keyed by chunk index.
class BagReader::ChunkCache {
 public:
  ChunkCache(size_t capacity, ChunkReadAhead* read_ahead)
      : slots_(std::max<size_t>(capacity, 1)), read_ahead_(read_ahead) {}

  // The decompressed bytes of chunk `chunk`, loading it on a miss.
  Status Get(BagReader* reader, uint32_t chunk, const uint8_t** data) {
    ++clock_;
    Slot* victim = &slots_[0];
    for (Slot& slot : slots_) {
      if (slot.chunk == static_cast<int64_t>(chunk)) {
        slot.last_use = clock_;
        *data = slot.buffer.data();
        return Status::Ok();
      }
      if (slot.last_use < victim->last_use) victim = &slot;
    }
    victim->chunk = -1;
    Status taken;
    if (read_ahead_ != nullptr && read_ahead_->Take(chunk, &victim->buffer, &taken)) {
      reader->CountChunkLoad(chunk);
      TILTCAL_RETURN_IF_ERROR(taken);
    } else {
      uint8_t* dst = victim->buffer.Reserve(std::max<size_t>(reader->chunks_[chunk].size, 1));
      TILTCAL_RETURN_IF_ERROR(reader->LoadChunk(chunk, &compressed_, dst));
    }
    victim->chunk = chunk;
    victim->last_use = clock_;
    *data = victim->buffer.data();
    return Status::Ok();
  }

 private:
  struct Slot {
    int64_t chunk = -1;
    uint64_t last_use = 0;
    ByteBuffer buffer;
  };
  std::vector<Slot> slots_;
  ChunkReadAhead* read_ahead_;
  std::vector<uint8_t> compressed_;
  uint64_t clock_ = 0;
};

BagReader::BagReader() = default;

BagReader::~BagReader() {
  if (fd_ >= 0) ::close(fd_);
}

Status BagReader::Error(uint64_t pos, const std::string& what) const {
  return Status::Error(path_ + ": record at byte " + std::to_string(pos) + ": " + what);
}

Status BagReader::ReadAt(uint64_t pos, size_t size, void* dst) const {
  if (pos > file_size_ || size > file_size_ - pos) {
    return Status::Error(path_ + ": read of " + std::to_string(size) + " bytes at byte " +
                         std::to_string(pos) + " runs past the end of the file (" +
                         std::to_string(file_size_) + " bytes; truncated?)");
  }
  auto* out = static_cast<char*>(dst);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pread(fd_, out + done, size - done, static_cast<off_t>(pos + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      return Status::Error(path_ + ": read error at byte " + std::to_string(pos + done) + ": " +
                           (n < 0 ? std::strerror(errno) : "unexpected end of file"));
    }
    done += static_cast<size_t>(n);
  }
  return Status::Ok();
}

Status BagReader::ReadRecordHeaderAt(uint64_t pos, std::string* buffer, RecordHeader* header,
                                     uint64_t* data_pos, uint32_t* data_len) const {
  if (pos > file_size_ || file_size_ - pos < 8) {
    return Error(pos, "record runs past the end of the file (" + std::to_string(file_size_) +
                          " bytes; truncated?)");
  }
  uint32_t header_len = 0;
  TILTCAL_RETURN_IF_ERROR(ReadAt(pos, 4, &header_len));
  if (header_len > kMaxHeaderBytes) {
    return Error(pos, "header length " + std::to_string(header_len) + " is implausible (> " +
                          std::to_string(kMaxHeaderBytes) + " bytes; corrupt bag?)");
  }
  if (header_len > file_size_ - pos - 8) {
    return Error(pos, "header length " + std::to_string(header_len) +
                          " runs past the end of the file (" + std::to_string(file_size_) +
                          " bytes; truncated?)");
  }
  buffer->resize(header_len + 4);
  TILTCAL_RETURN_IF_ERROR(ReadAt(pos + 4, header_len + 4, buffer->data()));
  *data_len = LoadU32Le(buffer->data() + header_len);
  *data_pos = pos + 8 + header_len;
  if (*data_len > file_size_ - *data_pos) {
    return Error(pos, "data length " + std::to_string(*data_len) +
                          " runs past the end of the file (" + std::to_string(file_size_) +
                          " bytes; truncated?)");
  }
  Status status = header->Parse(buffer->data(), header_len);
  if (!status.ok()) return Error(pos, status.message());
  return Status::Ok();
}

int BagReader::ConnectionSlot(uint32_t id) const {
  for (size_t i = 0; i < connections_.size(); ++i) {
    if (connections_[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

Status BagReader::AddConnection(const RecordHeader& header, const uint8_t* data, size_t size,
                                uint64_t pos) {
  Connection connection;
  Status status = header.GetU32("conn", &connection.id);
  if (status.ok()) status = header.GetString("topic", &connection.topic);
  RecordHeader inner;
  if (status.ok()) status = inner.Parse(data, size);
  if (!status.ok()) return Error(pos, "connection record: " + status.message());
  if (ConnectionSlot(connection.id) >= 0) return Status::Ok();  // seen in a chunk already
  // The inner block may lack `topic` (recorded live); the outer one is authoritative.
  if (inner.Has("type")) (void)inner.GetString("type", &connection.type);
  if (inner.Has("md5sum")) (void)inner.GetString("md5sum", &connection.md5sum);
  if (inner.Has("message_definition")) {
    (void)inner.GetString("message_definition", &connection.message_definition);
  }
  if (inner.Has("callerid")) (void)inner.GetString("callerid", &connection.callerid);
  connections_.push_back(std::move(connection));
  message_counts_.push_back(0);
  entries_.emplace_back();
  entries_loaded_.push_back(!indexed_);
  return Status::Ok();
}

Status BagReader::Open(const std::string& path) {
  path_ = path;
  TILTCAL_RETURN_IF_ERROR(OpenInputFile(path, &fd_, &file_size_));
  if (file_size_ == 0) return Status::Error(path + ": empty file (0 bytes), not a ROS bag");

  // Version line.
  char magic[16] = {};
  const size_t magic_size = static_cast<size_t>(std::min<uint64_t>(file_size_, sizeof(magic)));
  TILTCAL_RETURN_IF_ERROR(ReadAt(0, magic_size, magic));
  const std::string_view head(magic, magic_size);
  if (head.substr(0, kVersionLine.size()) != kVersionLine) {
    if (head.rfind("#ROSRECORD V1.2", 0) == 0 || head.rfind("#ROSBAG V1.", 0) == 0) {
      return Status::Error(path + ": ROS bag format V1.2 is not supported (only V2.0, "
                                  "written by ROS since 2010)");
    }
    if (head.rfind("#ROSBAG V", 0) == 0 || head.rfind("#ROSRECORD V", 0) == 0) {
      return Status::Error(path + ": unsupported ROS bag version '" +
                           std::string(head.substr(0, head.find('\n'))) + "' (only V2.0)");
    }
    if (head.rfind("SQLite format 3", 0) == 0) {
      return Status::Error(path + ": a ROS 2 sqlite3 bag (.db3); only ROS1 .bag files are "
                                  "supported");
    }
    if (head.rfind("\x89MCAP", 0) == 0) {
      return Status::Error(path + ": an MCAP file; only ROS1 .bag files are supported");
    }
    return Status::Error(path + ": not a ROS1 bag: wrong magic (expected \"#ROSBAG V2.0\")");
  }

  // Bag header record.
  const uint64_t header_pos = kVersionLine.size();
  std::string buffer;
  RecordHeader header;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  TILTCAL_RETURN_IF_ERROR(ReadRecordHeaderAt(header_pos, &buffer, &header, &data_pos, &data_len));  uint64_t index_pos = 0;
  uint32_t conn_count = 0;
  uint32_t chunk_count = 0;
  Status status = RequireOp(header, Op::kBagHeader, "the bag header record");
  if (status.ok()) status = header.GetU64("index_pos", &index_pos);
  if (status.ok()) status = header.GetU32("conn_count", &conn_count);
  if (status.ok()) status = header.GetU32("chunk_count", &chunk_count);
  if (!status.ok()) return Error(header_pos, "bag header: " + status.message());
  if (const std::string_view* encryptor = header.Find("encryptor");
      encryptor != nullptr && !encryptor->empty()) {
    return Status::Error(path + ": encrypted bag (encryptor=" + std::string(*encryptor) +
                         ") is not supported");
  }
  const uint64_t first_record_pos = data_pos + data_len;
  if (index_pos == 0) {
    indexed_ = false;
    return ScanUnindexed(first_record_pos);
  }
  if (index_pos < first_record_pos) {
    return Error(header_pos, "bag header: index_pos " + std::to_string(index_pos) +
                                 " points inside the bag header");
  }
  return ReadIndexed(index_pos, conn_count, chunk_count);
}

Status BagReader::ReadIndexed(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count) {
  if (index_pos > file_size_) {
    return Status::Error(path_ + ": bag is truncated: its index at byte " +
                         std::to_string(index_pos) + " lies past the end of the file (" +
                         std::to_string(file_size_) + " bytes)");
  }
  uint64_t pos = index_pos;
  TILTCAL_RETURN_IF_ERROR(ReadConnectionRecords(conn_count, &pos));
  TILTCAL_RETURN_IF_ERROR(ReadChunkInfos(chunk_count, pos));
  TILTCAL_RETURN_IF_ERROR(ReadChunkHeaders());
  std::sort(chunks_.begin(), chunks_.end(),
            [](const Chunk& a, const Chunk& b) { return a.pos < b.pos; });
  return Status::Ok();
}

Status BagReader::ReadConnectionRecords(uint32_t conn_count, uint64_t* pos) {
  std::string buffer;
  std::string data;
  RecordHeader header;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  for (uint32_t i = 0; i < conn_count; ++i) {
    TILTCAL_RETURN_IF_ERROR(ReadRecordHeaderAt(*pos, &buffer, &header, &data_pos, &data_len));
    const Status status = RequireOp(header, Op::kConnection,
                                    "connection record " + std::to_string(i + 1) + " of " +
                                        std::to_string(conn_count));
    if (!status.ok()) return Error(*pos, status.message());
    data.resize(data_len);
    TILTCAL_RETURN_IF_ERROR(ReadAt(data_pos, data_len, data.data()));
    TILTCAL_RETURN_IF_ERROR(AddConnection(
        header, reinterpret_cast<const uint8_t*>(data.data()), data.size(), *pos));
    *pos = data_pos + data_len;
  }
  return Status::Ok();
}

Status BagReader::ReadChunkInfos(uint32_t chunk_count, uint64_t pos) {
  std::string buffer;
  std::string data;
  RecordHeader header;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  std::set<uint64_t> chunk_positions;
  for (uint32_t i = 0; i < chunk_count; ++i) {
    TILTCAL_RETURN_IF_ERROR(ReadRecordHeaderAt(pos, &buffer, &header, &data_pos, &data_len));
    Chunk chunk;
    uint32_t version = 0;
    uint32_t count = 0;
    RosTime start;
    RosTime end;
    Status status = RequireOp(header, Op::kChunkInfo,
                              "chunk info record " + std::to_string(i + 1) + " of " +
                                  std::to_string(chunk_count));
    if (status.ok()) status = header.GetU32("ver", &version);
    if (status.ok() && version != kChunkInfoVersion) {
      status = Status::Error("chunk info version " + std::to_string(version) + " (expected 1)");
    }
    if (status.ok()) status = header.GetU64("chunk_pos", &chunk.pos);
    if (status.ok()) status = header.GetTime("start_time", &start);
    if (status.ok()) status = header.GetTime("end_time", &end);
    if (status.ok()) status = header.GetU32("count", &count);
    if (status.ok() && static_cast<uint64_t>(count) * 8 != data_len) {
      status = Status::Error("chunk info lists " + std::to_string(count) +
                             " connections but has " + std::to_string(data_len) +
                             " data bytes (expected " + std::to_string(uint64_t{count} * 8) + ")");
    }
    if (status.ok() && !chunk_positions.insert(chunk.pos).second) {
      status = Status::Error("chunk at byte " + std::to_string(chunk.pos) + " listed twice");
    }
    if (!status.ok()) return Error(pos, status.message());
    data.resize(data_len);
    TILTCAL_RETURN_IF_ERROR(ReadAt(data_pos, data_len, data.data()));
    uint64_t messages_in_chunk = 0;
    for (uint32_t k = 0; k < count; ++k) {
      const uint32_t conn = LoadU32Le(data.data() + 8 * k);
      const uint32_t messages = LoadU32Le(data.data() + 8 * k + 4);
      const int slot = ConnectionSlot(conn);
      if (slot < 0) {
        return Error(pos, "chunk info refers to unknown connection " + std::to_string(conn));
      }
      chunk.connection_counts.emplace_back(slot, messages);
      message_counts_[slot] += messages;
      messages_in_chunk += messages;
    }
    if (messages_in_chunk > 0) {
      start_ns_ = std::min(start_ns_, RosTimeToNs(start));
      end_ns_ = std::max(end_ns_, RosTimeToNs(end));
    }
    chunks_.push_back(std::move(chunk));
    pos = data_pos + data_len;
  }
  return Status::Ok();
}

// Chunk headers: compression, sizes; index data records follow the data.
Status BagReader::ReadChunkHeaders() {
  std::string buffer;
  RecordHeader header;
  uint8_t op = 0;
  for (Chunk& chunk : chunks_) {
    TILTCAL_RETURN_IF_ERROR(
        ReadRecordHeaderAt(chunk.pos, &buffer, &header, &chunk.data_pos, &chunk.data_len));
    Status status = header.GetOp(&op);
    if (status.ok() && op != static_cast<uint8_t>(Op::kChunk)) {
      status = Status::Error("chunk info points to a record with op " + std::to_string(op) +
                             " (" + OpName(op) + "), not a chunk");
    }
    if (status.ok()) status = ParseChunkHeader(header, &chunk);
    if (!status.ok()) return Error(chunk.pos, "chunk: " + status.message());
    chunk.index_pos = chunk.data_pos + chunk.data_len;
  }
  return Status::Ok();
}

Status BagReader::ReadChunkIndex(size_t chunk_index, const std::vector<size_t>& connection_slots) {
  const Chunk& chunk = chunks_[chunk_index];
  std::string buffer;
  RecordHeader header;
  uint64_t pos = chunk.index_pos;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  std::string data;
  for (size_t k = 0; k < chunk.connection_counts.size(); ++k) {
    TILTCAL_RETURN_IF_ERROR(ReadRecordHeaderAt(pos, &buffer, &header, &data_pos, &data_len));
    uint32_t version = 0;
    uint32_t conn = 0;
    uint32_t count = 0;
    Status status = RequireOp(header, Op::kIndexData,
                              "index data record " + std::to_string(k + 1) + " of " +
                                  std::to_string(chunk.connection_counts.size()) +
                                  " of the chunk at byte " + std::to_string(chunk.pos));
    if (status.ok()) status = header.GetU32("ver", &version);
    if (status.ok() && version != kIndexDataVersion) {
      status = Status::Error("index data version " + std::to_string(version) + " (expected 1)");
    }
    if (status.ok()) status = header.GetU32("conn", &conn);
    if (status.ok()) status = header.GetU32("count", &count);
    if (status.ok() && uint64_t{count} * kIndexEntrySize != data_len) {
      status = Status::Error("index data with " + std::to_string(count) + " entries has " +
                             std::to_string(data_len) + " data bytes");
    }
    int slot = -1;
    if (status.ok()) {
      slot = ConnectionSlot(conn);
      auto it = std::find_if(chunk.connection_counts.begin(), chunk.connection_counts.end(),
                             [&](const auto& c) { return c.first == slot; });
      if (slot < 0 || it == chunk.connection_counts.end()) {
        status = Status::Error("index data for connection " + std::to_string(conn) +
                               " which the chunk info of the chunk at byte " +
                               std::to_string(chunk.pos) + " does not list");
      } else if (it->second != count) {
        status = Status::Error("index data of connection " + std::to_string(conn) + " has " +
                               std::to_string(count) + " entries, the chunk info says " +
                               std::to_string(it->second));
      }
    }
    if (!status.ok()) return Error(pos, status.message());
    if (std::find(connection_slots.begin(), connection_slots.end(), static_cast<size_t>(slot)) !=
        connection_slots.end()) {
      data.resize(data_len);
      TILTCAL_RETURN_IF_ERROR(ReadAt(data_pos, data_len, data.data()));
      std::vector<Entry>& entries = entries_[slot];
      for (uint32_t i = 0; i < count; ++i) {
        const char* e = data.data() + i * kIndexEntrySize;
        const uint32_t offset = LoadU32Le(e + 8);
        if (offset >= chunk.size) {
          return Error(pos, "index entry " + std::to_string(i) + " has offset " +
                                std::to_string(offset) + " past the chunk size " +
                                std::to_string(chunk.size));
        }
        entries.push_back(
            Entry{RosTimeToNs(LoadRosTime(e)), static_cast<uint32_t>(chunk_index), offset});
      }
    }
    pos = data_pos + data_len;
  }
  return Status::Ok();
}

void BagReader::CountChunkLoad(size_t chunk_index) {
  const Chunk& chunk = chunks_[chunk_index];
  stats_.chunks_decompressed += 1;
  stats_.compressed_bytes_read += chunk.data_len;
  stats_.uncompressed_bytes += chunk.size;
}

Status BagReader::LoadChunk(size_t chunk_index, std::vector<uint8_t>* compressed, uint8_t* dst) {
  CountChunkLoad(chunk_index);
  return LoadChunkWith(chunk_index, &decompressor_, compressed, dst);
}

Status BagReader::LoadChunkWith(size_t chunk_index, ChunkDecompressor* decompressor,
                                std::vector<uint8_t>* compressed, uint8_t* dst) const {
  const Chunk& chunk = chunks_[chunk_index];
  if (chunk.compression == ChunkCompression::kNone) {
    if (chunk.data_len != chunk.size) {
      return Error(chunk.pos, "uncompressed chunk of size " + std::to_string(chunk.size) +
                                  " has " + std::to_string(chunk.data_len) + " data bytes");
    }
    return ReadAt(chunk.data_pos, chunk.data_len, dst);
  }
  if (compressed->size() < chunk.data_len) compressed->resize(chunk.data_len);
  TILTCAL_RETURN_IF_ERROR(ReadAt(chunk.data_pos, chunk.data_len, compressed->data()));
  Status status = decompressor->Decompress(chunk.compression, compressed->data(),
                                           chunk.data_len, dst, chunk.size);
  if (!status.ok()) {
    return Error(chunk.pos, std::string(ChunkCompressionName(chunk.compression)) +
                                " chunk (" + std::to_string(chunk.data_len) + " -> " +
                                std::to_string(chunk.size) + " bytes): " + status.message());
  }
  return Status::Ok();
}

namespace {

// One record inside a decompressed chunk buffer.
struct BufferRecord {
  RecordHeader header;
  uint8_t op = 0;
  const uint8_t* data = nullptr;
  uint32_t data_len = 0;
  size_t end = 0;  // offset just past the record
};

// Parses the record at `offset` of `buffer` (size `size`); every length must
// stay inside the buffer.
Status ParseBufferRecord(const uint8_t* buffer, size_t size, size_t offset, BufferRecord* r) {
  if (offset > size || size - offset < 4) {
    return Status::Error("record header length at chunk offset " + std::to_string(offset) +
                         " runs past the chunk end " + std::to_string(size));
  }
  const uint32_t header_len = LoadU32Le(buffer + offset);
  if (header_len > size - offset - 4 || size - offset - 4 - header_len < 4) {
    return Status::Error("record header at chunk offset " + std::to_string(offset) +
                         " (length " + std::to_string(header_len) +
                         ") runs past the chunk end " + std::to_string(size));
  }
  const size_t data_pos = offset + 4 + header_len + 4;
  r->data_len = LoadU32Le(buffer + data_pos - 4);
  if (r->data_len > size - data_pos) {
    return Status::Error("record data at chunk offset " + std::to_string(offset) + " (length " +
                         std::to_string(r->data_len) + ") runs past the chunk end " +
                         std::to_string(size));
  }
  r->data = buffer + data_pos;
  r->end = data_pos + r->data_len;
  Status status = r->header.Parse(buffer + offset + 4, header_len);
  if (status.ok()) status = r->header.GetOp(&r->op);
  if (!status.ok()) {
    return Status::Error("record at chunk offset " + std::to_string(offset) + ": " +
                         status.message());
  }
  return Status::Ok();
}

}  // namespace

void BagReader::AddSalvagedEntry(uint32_t conn, RosTime time, uint32_t chunk, uint32_t offset) {
  const int slot = ConnectionSlot(conn);
  if (slot < 0) return;  // message of a connection never described: unusable
  const int64_t time_ns = RosTimeToNs(time);
  entries_[slot].push_back(Entry{time_ns, chunk, offset});
  message_counts_[slot] += 1;
  start_ns_ = std::min(start_ns_, time_ns);
  end_ns_ = std::max(end_ns_, time_ns);
  ++num_salvaged_;
}

Status BagReader::IndexChunkRecords(const uint8_t* records, size_t size, uint32_t chunk_index,
                                    bool open, size_t* end) {
  const uint64_t chunk_pos = chunks_[chunk_index].pos;
  size_t offset = 0;
  while (offset < size) {
    BufferRecord record;
    TILTCAL_RETURN_IF_ERROR(ParseBufferRecord(records, size, offset, &record));
    if (record.op == static_cast<uint8_t>(Op::kConnection)) {
      TILTCAL_RETURN_IF_ERROR(
          AddConnection(record.header, record.data, record.data_len, chunk_pos));
    } else if (record.op == static_cast<uint8_t>(Op::kMessageData)) {
      uint32_t conn = 0;
      RosTime time;
      TILTCAL_RETURN_IF_ERROR(record.header.GetU32("conn", &conn));
      TILTCAL_RETURN_IF_ERROR(record.header.GetTime("time", &time));
      AddSalvagedEntry(conn, time, chunk_index, static_cast<uint32_t>(offset));
    } else if (open) {
      break;  // an open chunk has no size: any other record ends it
    }
    offset = record.end;
    *end = offset;
  }
  return Status::Ok();
}

Status BagReader::SalvageChunk(uint64_t pos, const RecordHeader& header, uint64_t data_pos,
                               uint32_t data_len, bool* stop) {
  Chunk chunk;
  chunk.pos = pos;
  chunk.data_pos = data_pos;
  chunk.data_len = data_len;
  Status status = ParseChunkHeader(header, &chunk);
  if (!status.ok()) {
    salvage_note_ = "stopped at a bad chunk at byte " + std::to_string(pos) + ": " +
                    status.message();
    *stop = true;
    return Status::Ok();
  }
  const uint32_t chunk_index = static_cast<uint32_t>(chunks_.size());
  const bool open = chunk.size == 0 && data_len == 0;
  if (open && chunk.compression != ChunkCompression::kNone) {
    salvage_note_ = std::string("the open ") + ChunkCompressionName(chunk.compression) +
                    " chunk at byte " + std::to_string(pos) +
                    " cannot be recovered (its compressor kept the data)";
    *stop = true;
    return Status::Ok();
  }
  chunks_.push_back(chunk);
  if (open) {
    *stop = true;  // its records run to the end of the file
    return SalvageOpenChunk(chunk_index);
  }
  // Not zero-filled: only the pages the decompressor writes are touched, so
  // a bz2 chunk that declares more than it holds costs what it holds.
  ByteBuffer records;
  uint8_t* dst = records.Reserve(std::max<size_t>(chunk.size, 1));
  std::vector<uint8_t> compressed;
  size_t end = 0;
  status = LoadChunk(chunk_index, &compressed, dst);
  if (status.ok()) {
    status = IndexChunkRecords(dst, chunk.size, chunk_index, /*open=*/false, &end);
  }
  if (!status.ok()) {
    salvage_note_ = "stopped at the damaged chunk at byte " + std::to_string(pos) + ": " +
                    status.message();
    *stop = true;
  }
  return Status::Ok();
}

Status BagReader::SalvageOpenChunk(uint32_t chunk_index) {
  Chunk& chunk = chunks_[chunk_index];
  std::vector<uint8_t> records(file_size_ - chunk.data_pos);
  TILTCAL_RETURN_IF_ERROR(ReadAt(chunk.data_pos, records.size(), records.data()));
  // The records end at the first one that is incomplete or of another kind.
  size_t end = 0;
  (void)IndexChunkRecords(records.data(), records.size(), chunk_index, /*open=*/true, &end);
  chunk.data_len = static_cast<uint32_t>(end);
  chunk.size = static_cast<uint32_t>(end);
  if (chunk.data_pos + end < file_size_) {
    salvage_note_ = "the open chunk at byte " + std::to_string(chunk.pos) + " ends with " +
                    std::to_string(file_size_ - chunk.data_pos - end) +
                    " bytes of an incomplete record";
  }
  return Status::Ok();
}

Status BagReader::ScanUnindexed(uint64_t first_record_pos) {
  std::string buffer;
  RecordHeader header;
  std::string data;
  uint64_t pos = first_record_pos;
  bool stop = false;
  while (pos < file_size_ && !stop) {
    uint64_t data_pos = 0;
    uint32_t data_len = 0;
    if (!ReadRecordHeaderAt(pos, &buffer, &header, &data_pos, &data_len).ok()) {
      salvage_note_ = "stopped at an incomplete record at byte " + std::to_string(pos) + " (" +
                      std::to_string(file_size_ - pos) + " bytes to the end of the file)";
      break;
    }
    uint8_t op = 0;
    if (!header.GetOp(&op).ok()) {
      salvage_note_ = "stopped at a record without op at byte " + std::to_string(pos);
      break;
    }
    if (op == static_cast<uint8_t>(Op::kConnection)) {
      data.resize(data_len);
      TILTCAL_RETURN_IF_ERROR(ReadAt(data_pos, data_len, data.data()));
      TILTCAL_RETURN_IF_ERROR(AddConnection(
          header, reinterpret_cast<const uint8_t*>(data.data()), data.size(), pos));
    } else if (op == static_cast<uint8_t>(Op::kChunk)) {
      TILTCAL_RETURN_IF_ERROR(SalvageChunk(pos, header, data_pos, data_len, &stop));
    } else if (op != static_cast<uint8_t>(Op::kIndexData) &&
               op != static_cast<uint8_t>(Op::kChunkInfo)) {
      // Index records are skipped: the scan rebuilds the index from the chunks.
      salvage_note_ = "stopped at an unexpected record (op " + std::to_string(op) + ", " +
                      OpName(op) + ") at byte " + std::to_string(pos);
      break;
    }
    pos = data_pos + data_len;
  }
  for (auto& entries : entries_) {
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
      return std::tie(a.time_ns, a.chunk, a.offset) < std::tie(b.time_ns, b.chunk, b.offset);
    });
  }
  return Status::Ok();
}

std::vector<std::string> BagReader::TopicsOfType(const std::string& type) const {
  std::set<std::string> topics;
  for (const Connection& c : connections_) {
    if (c.type == type) topics.insert(c.topic);
  }
  return {topics.begin(), topics.end()};
}

std::vector<std::string> BagReader::Topics() const {
  std::set<std::string> topics;
  for (const Connection& c : connections_) topics.insert(c.topic);
  return {topics.begin(), topics.end()};
}

std::string BagReader::TopicType(const std::string& topic) const {
  for (const Connection& c : connections_) {
    if (c.topic == topic) return c.type;
  }
  return "";
}

int64_t BagReader::MessageCount(const std::string& topic) const {
  int64_t count = 0;
  for (size_t i = 0; i < connections_.size(); ++i) {
    if (connections_[i].topic == topic) count += message_counts_[i];
  }
  return count;
}

int64_t BagReader::TotalMessageCount() const {
  int64_t count = 0;
  for (int64_t c : message_counts_) count += c;
  return count;
}

bool BagReader::TimeRange(int64_t* start_ns, int64_t* end_ns) const {
  if (start_ns_ > end_ns_) return false;
  *start_ns = start_ns_;
  *end_ns = end_ns_;
  return true;
}

Status BagReader::LoadEntries(const std::vector<size_t>& slots) {
  std::vector<size_t> to_load;
  for (size_t slot : slots) {
    if (!entries_loaded_[slot]) to_load.push_back(slot);
  }
  if (to_load.empty()) return Status::Ok();
  for (size_t c = 0; c < chunks_.size(); ++c) {
    const bool wanted = std::any_of(
        chunks_[c].connection_counts.begin(), chunks_[c].connection_counts.end(),
        [&](const auto& cc) {
          return std::find(to_load.begin(), to_load.end(), static_cast<size_t>(cc.first)) !=
                 to_load.end();
        });
    if (wanted) TILTCAL_RETURN_IF_ERROR(ReadChunkIndex(c, to_load));
  }
  for (size_t slot : to_load) entries_loaded_[slot] = true;
  return Status::Ok();
}

std::vector<BagReader::Item> BagReader::MergedItems(const std::vector<size_t>& slots,
                                                    const ReadOptions& options) const {
  std::vector<Item> items;
  size_t total = 0;
  for (size_t slot : slots) total += entries_[slot].size();
  items.reserve(total);
  for (size_t slot : slots) {
    for (const Entry& e : entries_[slot]) {
      if (e.time_ns >= options.start_ns && e.time_ns < options.end_ns) {
        items.push_back(Item{e.time_ns, e.chunk, e.offset, static_cast<uint32_t>(slot)});
      }
    }
  }
  // chunks_ is sorted by file position, so the chunk index orders as chunk_pos.
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return std::tie(a.time_ns, a.chunk, a.offset) < std::tie(b.time_ns, b.chunk, b.offset);
  });
  return items;
}

Status BagReader::ReadMessages(const ReadOptions& options,
                               const std::function<Status(const MessageView&)>& fn) {
  std::vector<size_t> slots;
  for (size_t i = 0; i < connections_.size(); ++i) {
    if (options.topics.empty() ||
        std::find(options.topics.begin(), options.topics.end(), connections_[i].topic) !=
            options.topics.end()) {
      slots.push_back(i);
    }
  }
  for (const std::string& topic : options.topics) {
    if (MessageCount(topic) == 0 && TopicType(topic).empty()) {
      return Status::Error(path_ + ": no topic '" + topic + "' in the bag");
    }
  }
  TILTCAL_RETURN_IF_ERROR(LoadEntries(slots));
  const std::vector<Item> items = MergedItems(slots, options);

  std::unique_ptr<ChunkReadAhead> read_ahead;
  if (options.read_ahead_chunks > 0) {
    // The chunks in the order of their first use; later uses hit the cache
    // (or, after an eviction, load on this thread).
    std::vector<uint32_t> order;
    std::vector<bool> seen(chunks_.size(), false);
    for (const Item& item : items) {
      if (!seen[item.chunk]) {
        seen[item.chunk] = true;
        order.push_back(item.chunk);
      }
    }
    if (order.size() > 1) {
      read_ahead =
          std::make_unique<ChunkReadAhead>(this, std::move(order), options.read_ahead_chunks);
    }
  }
  ChunkCache cache(options.chunk_cache_size, read_ahead.get());
  MessageView view;
  for (size_t i = 0; i < items.size(); ++i) {
    const Item& item = items[i];
    const Chunk& chunk = chunks_[item.chunk];
    const uint8_t* buffer = nullptr;
    TILTCAL_RETURN_IF_ERROR(cache.Get(this, item.chunk, &buffer));
    // Skip connection records placed before the message (ros_comm does too).
    size_t offset = item.offset;
    BufferRecord record;
    for (;;) {
      Status status = ParseBufferRecord(buffer, chunk.size, offset, &record);
      if (!status.ok()) return Error(chunk.pos, "chunk: " + status.message());
      if (record.op != static_cast<uint8_t>(Op::kConnection)) break;
      offset = record.end;
    }
    if (record.op != static_cast<uint8_t>(Op::kMessageData)) {
      return Error(chunk.pos, "chunk: the index points to a record with op " +
                                  std::to_string(record.op) + " (" + OpName(record.op) +
                                  ") at chunk offset " + std::to_string(offset) +
                                  ", not a message");
    }
    view.connection = &connections_[item.slot];
    view.time_ns = item.time_ns;
    view.chunk_pos = chunk.pos;
    view.offset = static_cast<uint32_t>(offset);
    view.sequence = i;
    view.data = record.data;
    view.size = record.data_len;
    TILTCAL_RETURN_IF_ERROR(fn(view));
  }
  return Status::Ok();
}

std::map<std::string, int64_t> BagReader::ChunkCompressions() const {
  std::map<std::string, int64_t> compressions;
  for (const Chunk& chunk : chunks_) ++compressions[ChunkCompressionName(chunk.compression)];
  return compressions;
}

}  // namespace tiltcal::ros1
