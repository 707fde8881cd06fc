#include "bag/ros1/bag_salvage.h"

#include <algorithm>
#include <tuple>
#include <vector>

#include "bag/ros1/chunk_cache.h"

namespace tiltcal::ros1 {
namespace {

class UnindexedScan {
 public:
  UnindexedScan(const RecordFile& file, ChunkDecompressor* decompressor, ReaderStats* stats,
                BagIndex* index, SalvageResult* result)
      : file_(file), decompressor_(decompressor), stats_(stats), index_(index),
        result_(result) {}

  Status Scan(uint64_t first_record_pos);

 private:
  // Reads the chunk record at `pos` and indexes its records; sets *stop
  // (with the note saying why) when nothing after it can be trusted. Errors
  // only for I/O failures.
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
  Status AddConnection(const RecordHeader& header, const uint8_t* data, size_t size,
                       uint64_t pos);
  void AddSalvagedEntry(uint32_t conn, RosTime time, uint32_t chunk, uint32_t offset);

  const RecordFile& file_;
  ChunkDecompressor* decompressor_;
  ReaderStats* stats_;
  BagIndex* index_;
  SalvageResult* result_;
};

Status UnindexedScan::AddConnection(const RecordHeader& header, const uint8_t* data, size_t size,
                                    uint64_t pos) {
  const Status status = index_->AddConnection(header, data, size, /*entries_loaded=*/true);
  if (!status.ok()) return file_.Error(pos, status.message());
  return Status::Ok();
}

void UnindexedScan::AddSalvagedEntry(uint32_t conn, RosTime time, uint32_t chunk,
                                     uint32_t offset) {
  const int slot = index_->ConnectionSlot(conn);
  if (slot < 0) return;  // message of a connection never described: unusable
  const int64_t time_ns = RosTimeToNs(time);
  index_->entries[slot].push_back(IndexEntry{time_ns, chunk, offset});
  index_->message_counts[slot] += 1;
  index_->start_ns = std::min(index_->start_ns, time_ns);
  index_->end_ns = std::max(index_->end_ns, time_ns);
  ++result_->num_messages;
}

Status UnindexedScan::IndexChunkRecords(const uint8_t* records, size_t size,
                                        uint32_t chunk_index, bool open, size_t* end) {
  const uint64_t chunk_pos = index_->chunks[chunk_index].pos;
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

Status UnindexedScan::SalvageChunk(uint64_t pos, const RecordHeader& header, uint64_t data_pos,
                                   uint32_t data_len, bool* stop) {
  Chunk chunk;
  chunk.pos = pos;
  chunk.data_pos = data_pos;
  chunk.data_len = data_len;
  Status status = ParseChunkHeader(header, &chunk);
  if (!status.ok()) {
    result_->note = "stopped at a bad chunk at byte " + std::to_string(pos) + ": " +
                    status.message();
    *stop = true;
    return Status::Ok();
  }
  const uint32_t chunk_index = static_cast<uint32_t>(index_->chunks.size());
  const bool open = chunk.size == 0 && data_len == 0;
  if (open && chunk.compression != ChunkCompression::kNone) {
    result_->note = std::string("the open ") + ChunkCompressionName(chunk.compression) +
                    " chunk at byte " + std::to_string(pos) +
                    " cannot be recovered (its compressor kept the data)";
    *stop = true;
    return Status::Ok();
  }
  index_->chunks.push_back(chunk);
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
  CountChunkLoad(chunk, stats_);
  status = LoadChunk(file_, chunk, decompressor_, &compressed, dst);
  if (status.ok()) {
    status = IndexChunkRecords(dst, chunk.size, chunk_index, /*open=*/false, &end);
  }
  if (!status.ok()) {
    result_->note = "stopped at the damaged chunk at byte " + std::to_string(pos) + ": " +
                    status.message();
    *stop = true;
  }
  return Status::Ok();
}

Status UnindexedScan::SalvageOpenChunk(uint32_t chunk_index) {
  Chunk& chunk = index_->chunks[chunk_index];
  std::vector<uint8_t> records(file_.size() - chunk.data_pos);
  TILTCAL_RETURN_IF_ERROR(file_.ReadAt(chunk.data_pos, records.size(), records.data()));
  // The records end at the first one that is incomplete or of another kind.
  size_t end = 0;
  (void)IndexChunkRecords(records.data(), records.size(), chunk_index, /*open=*/true, &end);
  chunk.data_len = static_cast<uint32_t>(end);
  chunk.size = static_cast<uint32_t>(end);
  if (chunk.data_pos + end < file_.size()) {
    result_->note = "the open chunk at byte " + std::to_string(chunk.pos) + " ends with " +
                    std::to_string(file_.size() - chunk.data_pos - end) +
                    " bytes of an incomplete record";
  }
  return Status::Ok();
}

Status UnindexedScan::Scan(uint64_t first_record_pos) {
  std::string buffer;
  RecordHeader header;
  std::string data;
  uint64_t pos = first_record_pos;
  bool stop = false;
  while (pos < file_.size() && !stop) {
    uint64_t data_pos = 0;
    uint32_t data_len = 0;
    if (!file_.ReadRecordHeaderAt(pos, &buffer, &header, &data_pos, &data_len).ok()) {
      result_->note = "stopped at an incomplete record at byte " + std::to_string(pos) + " (" +
                      std::to_string(file_.size() - pos) + " bytes to the end of the file)";
      break;
    }
    uint8_t op = 0;
    if (!header.GetOp(&op).ok()) {
      result_->note = "stopped at a record without op at byte " + std::to_string(pos);
      break;
    }
    if (op == static_cast<uint8_t>(Op::kConnection)) {
      data.resize(data_len);
      TILTCAL_RETURN_IF_ERROR(file_.ReadAt(data_pos, data_len, data.data()));
      TILTCAL_RETURN_IF_ERROR(AddConnection(
          header, reinterpret_cast<const uint8_t*>(data.data()), data.size(), pos));
    } else if (op == static_cast<uint8_t>(Op::kChunk)) {
      TILTCAL_RETURN_IF_ERROR(SalvageChunk(pos, header, data_pos, data_len, &stop));
    } else if (op != static_cast<uint8_t>(Op::kIndexData) &&
               op != static_cast<uint8_t>(Op::kChunkInfo)) {
      // Index records are skipped: the scan rebuilds the index from the chunks.
      result_->note = "stopped at an unexpected record (op " + std::to_string(op) + ", " +
                      OpName(op) + ") at byte " + std::to_string(pos);
      break;
    }
    pos = data_pos + data_len;
  }
  for (auto& entries : index_->entries) {
    std::sort(entries.begin(), entries.end(), [](const IndexEntry& a, const IndexEntry& b) {
      return std::tie(a.time_ns, a.chunk, a.offset) < std::tie(b.time_ns, b.chunk, b.offset);
    });
  }
  return Status::Ok();
}

}  // namespace

Status SalvageUnindexedBag(const RecordFile& file, uint64_t first_record_pos,
                           ChunkDecompressor* decompressor, ReaderStats* stats, BagIndex* index,
                           SalvageResult* result) {
  return UnindexedScan(file, decompressor, stats, index, result).Scan(first_record_pos);
}

}  // namespace tiltcal::ros1
