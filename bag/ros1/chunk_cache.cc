#include "bag/ros1/chunk_cache.h"

#include <algorithm>
#include <new>
#include <string>
#include <utility>

namespace tiltcal::ros1 {

uint8_t* ByteBuffer::Reserve(size_t size) {
  if (size > capacity_) {
    constexpr size_t kGranule = size_t{1} << 16;
    const size_t grown = size + size / 8;
    capacity_ = std::max(size, (grown + kGranule - 1) / kGranule * kGranule);
    data_.reset(new uint8_t[capacity_]);
  }
  return data_.get();
}

void ByteBuffer::Swap(ByteBuffer* other) {
  std::swap(data_, other->data_);
  std::swap(capacity_, other->capacity_);
}

Status LoadChunk(const RecordFile& file, const Chunk& chunk, ChunkDecompressor* decompressor,
                 std::vector<uint8_t>* compressed, uint8_t* dst) {
  if (chunk.compression == ChunkCompression::kNone) {
    if (chunk.data_len != chunk.size) {
      return file.Error(chunk.pos, "uncompressed chunk of size " + std::to_string(chunk.size) +
                                       " has " + std::to_string(chunk.data_len) + " data bytes");
    }
    return file.ReadAt(chunk.data_pos, chunk.data_len, dst);
  }
  if (compressed->size() < chunk.data_len) compressed->resize(chunk.data_len);
  TILTCAL_RETURN_IF_ERROR(file.ReadAt(chunk.data_pos, chunk.data_len, compressed->data()));
  Status status = decompressor->Decompress(chunk.compression, compressed->data(),
                                           chunk.data_len, dst, chunk.size);
  if (!status.ok()) {
    return file.Error(chunk.pos, std::string(ChunkCompressionName(chunk.compression)) +
                                     " chunk (" + std::to_string(chunk.data_len) + " -> " +
                                     std::to_string(chunk.size) + " bytes): " + status.message());
  }
  return Status::Ok();
}

void CountChunkLoad(const Chunk& chunk, ReaderStats* stats) {
  stats->chunks_decompressed += 1;
  stats->compressed_bytes_read += chunk.data_len;
  stats->uncompressed_bytes += chunk.size;
}

ChunkReadAhead::ChunkReadAhead(const RecordFile& file, const std::vector<Chunk>& chunks,
                               std::vector<uint32_t> order, size_t depth)
    : file_(file), chunks_(chunks), order_(std::move(order)),
      depth_(std::max<size_t>(depth, 1)) {
  thread_ = std::thread([this] { Work(); });
}

ChunkReadAhead::~ChunkReadAhead() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

bool ChunkReadAhead::Take(uint32_t chunk, ByteBuffer* buffer, Status* status) {
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

void ChunkReadAhead::Work() {
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
    const Chunk& chunk = chunks_[order_[next]];
    Status status;
    try {  // an exception would end the process from this thread
      uint8_t* dst = buffer.Reserve(std::max<size_t>(chunk.size, 1));
      status = LoadChunk(file_, chunk, &decompressor, &compressed, dst);
    } catch (const std::bad_alloc&) {
      status = Status::Error(file_.path() + ": chunk at byte " + std::to_string(chunk.pos) +
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

ChunkCache::ChunkCache(const RecordFile& file, const std::vector<Chunk>& chunks,
                       ChunkDecompressor* decompressor, ReaderStats* stats, size_t capacity,
                       ChunkReadAhead* read_ahead)
    : file_(file), chunks_(chunks), decompressor_(decompressor), stats_(stats),
      slots_(std::max<size_t>(capacity, 1)), read_ahead_(read_ahead) {}

Status ChunkCache::Get(uint32_t chunk, const uint8_t** data) {
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
    CountChunkLoad(chunks_[chunk], stats_);
    TILTCAL_RETURN_IF_ERROR(taken);
  } else {
    uint8_t* dst = victim->buffer.Reserve(std::max<size_t>(chunks_[chunk].size, 1));
    CountChunkLoad(chunks_[chunk], stats_);
    TILTCAL_RETURN_IF_ERROR(LoadChunk(file_, chunks_[chunk], decompressor_, &compressed_, dst));
  }
  victim->chunk = chunk;
  victim->last_use = clock_;
  *data = victim->buffer.data();
  return Status::Ok();
}

}  // namespace tiltcal::ros1
