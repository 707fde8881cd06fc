// McapReader::WalkDataSection() and the recovery from damaged records (see
// the top of mcap_reader.h).

#include <algorithm>
#include <cstring>

#include "bag/mcap/mcap_reader.h"

namespace tiltcal::mcap {
namespace {

// More damaged records than this: not a recording worth salvaging.
constexpr int kMaxDamagedRecords = 100;

}  // namespace

// The record at one offset of the walk: its prefix, and why it is damaged
// ("" when it is not).
struct McapReader::WalkedRecord {
  uint64_t offset = 0;
  uint8_t opcode = 0;
  uint64_t length = 0;
  std::string damage;
  // entries_ and chunks_ before the record was read.
  size_t entries_before = 0;
  size_t chunks_before = 0;
};

// What the walk keeps from record to record.
struct McapReader::Walk {
  size_t listed = 0;     // the chunks the summary listed (sorted by offset): not read again
  bool summary = false;  // the summary was read
  size_t unlisted_chunks = 0;
  size_t unlisted_entries = 0;
  uint64_t first_unlisted = 0;
  int damaged = 0;
  uint64_t skipped_bytes = 0;
  // The last record read whole: where it starts, its opcode, and how many
  // entries and chunks there were before it.
  struct Last {
    bool valid = false;
    uint64_t offset = 0;
    uint8_t opcode = 0;
    size_t entries = 0;
    size_t chunks = 0;
  } last;
  std::vector<uint8_t> content;
};

Status McapReader::WalkDataSection() {
  Walk walk;
  walk.listed = chunks_.size();
  walk.summary = indexed_;
  uint64_t offset = header_end_;
  while (true) {
    if (complete_ && offset == data_end_) break;  // no DataEnd record: tolerated
    WalkedRecord record;
    bool end = false;
    TILTCAL_RETURN_IF_ERROR(ReadWalkedPrefix(offset, &record, &end));
    if (end) break;
    TILTCAL_RETURN_IF_ERROR(MendChunkLength(&record));
    record.entries_before = entries_.size();
    record.chunks_before = chunks_.size();
    if (record.damage.empty()) TILTCAL_RETURN_IF_ERROR(IndexWalkedRecord(&record, &walk));
    if (record.damage.empty()) {
      walk.last = {true, offset, record.opcode, record.entries_before, record.chunks_before};
      offset += kRecordPrefixBytes + record.length;
      continue;
    }
    bool mended = false;
    TILTCAL_RETURN_IF_ERROR(MendLastChunkLength(record, &walk, &mended, &offset));
    if (mended) continue;
    TILTCAL_RETURN_IF_ERROR(SkipDamagedRecord(record, &walk, &offset));
  }
  DropMessagesWithoutChannel();
  WarnAboutWalk(walk);
  return Status::Ok();
}

Status McapReader::ReadWalkedPrefix(uint64_t offset, WalkedRecord* record, bool* end) {
  record->offset = offset;
  if (offset + kRecordPrefixBytes > data_end_) {
    if (!complete_) {
      salvage_note_ = "the recording ends at byte " + std::to_string(file_size_) +
                      " without its DataEnd record";
      *end = true;
      return Status::Ok();
    }
    record->damage = "the data section ends at byte " + std::to_string(data_end_) +
                     " inside its 9-byte prefix";
    return Status::Ok();
  }
  uint8_t prefix[kRecordPrefixBytes];
  TILTCAL_RETURN_IF_ERROR(ReadAt(offset, kRecordPrefixBytes, prefix));
  const uint8_t opcode = prefix[0];
  const uint64_t length = LoadU64(prefix + 1);
  record->opcode = opcode;
  record->length = length;
  const uint64_t room = data_end_ - offset - kRecordPrefixBytes;
  if ((!complete_ && (opcode == kDataEnd || opcode == kFooter)) ||
      (opcode == kDataEnd && length == room)) {
    *end = true;
    return Status::Ok();
  }
  if (length > room) {
    if (!complete_) {
      salvage_note_ = "the recording ends inside the " + OpcodeName(opcode) +
                      " record at byte " + std::to_string(offset) + " (" +
                      std::to_string(file_size_) + " bytes): what follows it is lost";
      *end = true;
      return Status::Ok();
    }
    record->damage = "length " + std::to_string(length) +
                     " runs past the end of the data section at byte " +
                     std::to_string(data_end_);
  } else if (opcode == kDataEnd) {
    record->damage = "it ends at byte " + std::to_string(offset + kRecordPrefixBytes + length) +
                     ", not at the end of the data section (byte " +
                     std::to_string(data_end_) + ")";
  } else if (opcode == 0 || opcode == kHeader || opcode == kFooter) {
    record->damage = "no " + OpcodeName(opcode) + " record belongs in the data section";
  }
  return Status::Ok();
}

Status McapReader::MendChunkLength(WalkedRecord* record) {
  if (record->damage.empty() || record->opcode != kChunk ||
      record->offset + kRecordPrefixBytes > data_end_) {
    return Status::Ok();
  }
  // Only the length is damaged when the chunk's own fields give one from
  // which the records after it chain onto the end of the data section.
  uint64_t by_fields = 0;
  TILTCAL_RETURN_IF_ERROR(ChunkLengthByItsFields(record->offset, &by_fields));
  if (by_fields != 0 && by_fields != record->length) {
    warnings_.push_back(DamagedChunkLength(record->offset, record->length, by_fields));
    record->length = by_fields;
    record->damage.clear();
  }
  return Status::Ok();
}

Status McapReader::IndexWalkedRecord(WalkedRecord* record, Walk* walk) {
  const uint64_t offset = record->offset;
  const uint64_t length = record->length;
  std::vector<uint8_t>& content = walk->content;
  if (record->opcode == kChunk) {
    const bool in_summary =
        std::binary_search(chunks_.begin(), chunks_.begin() + static_cast<long>(walk->listed),
                           Chunk{offset, 0, 0},
                           [](const Chunk& a, const Chunk& b) { return a.offset < b.offset; });
    if (in_summary) return Status::Ok();
    if (length > kMaxRecordBytes) {
      return Error(offset, "Chunk record of " + std::to_string(length) + " bytes");
    }
    content.resize(length);
    TILTCAL_RETURN_IF_ERROR(ReadAt(offset + kRecordPrefixBytes, length, content.data()));
    ChunkRecord chunk;
    Status status = ParseChunk(content.data(), content.size(), &chunk);
    if (!status.ok() && !complete_) return Error(offset, "Chunk: " + status.message());
    if (!status.ok()) {
      record->damage = status.message();
      return Status::Ok();
    }
    const auto index = static_cast<uint32_t>(chunks_.size());
    chunks_.push_back({offset, kRecordPrefixBytes + length, chunk.uncompressed_size});
    // Decompressed into the cache: the first ReadMessages() finds it there.
    std::vector<uint8_t>* records = CacheSlot(index, chunk.uncompressed_size);
    status = decompressor_.Decompress(chunk, records);
    if (!status.ok()) return Error(offset, "Chunk: " + status.message());
    if (!chunk.compression.empty()) ++chunks_decompressed_;
    cached_bytes_ += records->size();
    TILTCAL_RETURN_IF_ERROR(IndexRecords(records->data(), records->size(), index, offset));
    if (walk->summary) {
      if (walk->unlisted_chunks++ == 0) walk->first_unlisted = offset;
      walk->unlisted_entries += entries_.size() - record->entries_before;
    }
  } else if (record->opcode == kSchema || record->opcode == kChannel ||
             record->opcode == kMessage) {
    content.resize(kRecordPrefixBytes + length);
    TILTCAL_RETURN_IF_ERROR(ReadAt(offset, content.size(), content.data()));
    Status status = IndexRecords(content.data(), content.size(), kNoChunk, offset);
    if (!status.ok() && !complete_) return status;
    if (!status.ok()) record->damage = OpcodeName(record->opcode) + " does not parse";
  }
  return Status::Ok();
}

Status McapReader::MendLastChunkLength(const WalkedRecord& record, Walk* walk, bool* mended,
                                       uint64_t* offset) {
  // A damaged record that is no record at all (an opcode no record starts
  // with) after a chunk read whole by its own fields: only the chunk's
  // length overshoots.
  Walk::Last& last = walk->last;
  if (CanStartRecord(record.opcode) || !last.valid || last.opcode != kChunk) return Status::Ok();
  uint64_t by_fields = 0;
  TILTCAL_RETURN_IF_ERROR(ChunkLengthByItsFields(last.offset, &by_fields));
  const uint64_t resume = last.offset + kRecordPrefixBytes + by_fields;
  if (by_fields == 0 || resume == record.offset) return Status::Ok();
  warnings_.push_back(DamagedChunkLength(
      last.offset, record.offset - last.offset - kRecordPrefixBytes, by_fields));
  for (size_t c = last.chunks; c < chunks_.size(); ++c) {
    chunks_[c].length = kRecordPrefixBytes + by_fields;
  }
  last.valid = false;
  *offset = resume;
  *mended = true;
  return Status::Ok();
}

Status McapReader::SkipDamagedRecord(const WalkedRecord& record, Walk* walk, uint64_t* offset) {
  const uint64_t at = record.offset;
  if (++walk->damaged > kMaxDamagedRecords) {
    return Error(at, "more than " + std::to_string(kMaxDamagedRecords) +
                         " damaged records; the last: " + record.damage);
  }
  // When it is no record at all (an opcode no record starts with), the
  // length of the record before it is the damaged one: that record and what
  // it gave are dropped.
  const Walk::Last& last = walk->last;
  std::string what = "the " + OpcodeName(record.opcode) + " record at byte " +
                     std::to_string(at) + " (" + record.damage + ")";
  uint64_t skip_from = at;
  size_t dropped = 0;
  if (!CanStartRecord(record.opcode) && last.valid) {
    what = "the " + OpcodeName(last.opcode) + " record at byte " + std::to_string(last.offset) +
           " (its length leads to byte " + std::to_string(at) + ", where no record starts)";
    skip_from = last.offset;
    dropped = entries_.size() - last.entries;
    entries_.resize(last.entries);
    for (size_t c = last.chunks; c < chunks_.size(); ++c) {
      cache_.remove_if([&](const CachedChunk& cached) { return cached.chunk == c; });
    }
    if (chunks_.size() > last.chunks) chunks_.resize(last.chunks);
  } else {
    entries_.resize(record.entries_before);
    chunks_.resize(record.chunks_before);
  }
  cached_bytes_ = 0;
  for (const CachedChunk& cached : cache_) cached_bytes_ += cached.records.size();
  uint64_t resume = data_end_;
  TILTCAL_RETURN_IF_ERROR(FindResumeOffset(skip_from + 1, walk->listed, &resume));
  walk->skipped_bytes += resume - skip_from;
  std::string resumed = "nothing after it chains onto the end of the data section";
  if (resume < data_end_) {
    uint8_t resume_opcode = 0;
    TILTCAL_RETURN_IF_ERROR(ReadAt(resume, 1, &resume_opcode));
    resumed = "reading resumed at the " + OpcodeName(resume_opcode) + " record at byte " +
              std::to_string(resume);
  }
  warnings_.push_back(path_ + ": damaged " + what + ": bytes " + std::to_string(skip_from) +
                      " to " + std::to_string(resume) + " skipped (" +
                      std::to_string(resume - skip_from) + " bytes" +
                      (dropped > 0 ? ", with the " + std::to_string(dropped) +
                                         " messages read from that record"
                                   : "") +
                      "); " + resumed);
  walk->last.valid = false;
  *offset = resume;
  return Status::Ok();
}

void McapReader::DropMessagesWithoutChannel() {
  // Messages of channels no Channel record defines (their Channel record
  // was in a damaged record) cannot be given a topic.
  const auto defined = [this](const Entry& e) {
    return e.channel < channels_.size() && channels_[e.channel] != nullptr;
  };
  const auto without_channel = static_cast<size_t>(
      std::count_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return !defined(e); }));
  if (without_channel == 0) return;
  entries_.erase(std::remove_if(entries_.begin(), entries_.end(),
                                [&](const Entry& e) { return !defined(e); }),
                 entries_.end());
  warnings_.push_back(path_ + ": " + std::to_string(without_channel) +
                      " messages on channels that no Channel record defines left out (their "
                      "topic is unknown)");
}

void McapReader::WarnAboutWalk(const Walk& walk) {
  if (walk.damaged > 0) {
    warnings_.push_back(path_ + ": " + std::to_string(walk.damaged) + " damaged record(s), " +
                        std::to_string(walk.skipped_bytes) + " bytes skipped; " +
                        std::to_string(entries_.size()) +
                        " messages read from the rest of the file");
  }
  if (walk.unlisted_chunks > 0) {
    warnings_.push_back(path_ + ": the summary disagrees with the data section: it lists " +
                        std::to_string(walk.listed) + " chunks, the data section holds " +
                        std::to_string(walk.listed + walk.unlisted_chunks) + "; the " +
                        std::to_string(walk.unlisted_chunks) +
                        " chunk(s) it omits (the first at byte " +
                        std::to_string(walk.first_unlisted) + ", " +
                        std::to_string(walk.unlisted_entries) +
                        " messages) were read from the data section");
  }
}

Status McapReader::FindResumeOffset(uint64_t from, size_t listed, uint64_t* resume) {
  *resume = data_end_;
  // Inside a chunk the summary lists: its records are read from the chunk.
  auto inside_listed_chunk = [&](uint64_t offset) {
    const auto end = chunks_.begin() + static_cast<long>(listed);
    auto it = std::upper_bound(chunks_.begin(), end, offset,
                               [](uint64_t o, const Chunk& c) { return o < c.offset; });
    return it != chunks_.begin() && offset < std::prev(it)->offset + std::prev(it)->length &&
           offset != std::prev(it)->offset;
  };
  std::vector<uint8_t> window;
  constexpr uint64_t kWindowBytes = uint64_t{1} << 20;
  for (uint64_t p = from; p + kRecordPrefixBytes <= data_end_;) {
    const uint64_t n = std::min(kWindowBytes, data_end_ - p);
    window.resize(n);
    TILTCAL_RETURN_IF_ERROR(ReadAt(p, n, window.data()));
    for (uint64_t i = 0; i + kRecordPrefixBytes <= n; ++i) {
      const uint64_t q = p + i;
      if (!CanStartRecord(window[i]) ||
          LoadU64(&window[i + 1]) > data_end_ - q - kRecordPrefixBytes || inside_listed_chunk(q)) {
        continue;
      }
      bool chains = false;
      TILTCAL_RETURN_IF_ERROR(ChainsToDataEnd(q, &chains));
      if (chains) {
        *resume = q;
        return Status::Ok();
      }
    }
    p += n - (kRecordPrefixBytes - 1);  // the windows overlap by a prefix less one byte
  }
  return Status::Ok();
}

std::string McapReader::DamagedChunkLength(uint64_t offset, uint64_t declared,
                                           uint64_t by_fields) const {
  return path_ + ": damaged length of the Chunk record at byte " + std::to_string(offset) +
         ": it declares " + std::to_string(declared) + " bytes, its fields give " +
         std::to_string(by_fields) +
         ", after which the records follow; read with that length, nothing skipped";
}

Status McapReader::ChunkLengthByItsFields(uint64_t offset, uint64_t* length) {
  *length = 0;
  // start, end, uncompressed_size (u64), crc, compression length (u32).
  constexpr uint64_t kFixed = 8 + 8 + 8 + 4 + 4;
  constexpr uint32_t kMaxCompressionName = 64;
  const uint64_t room = data_end_ - offset - kRecordPrefixBytes;
  if (room < kFixed) return Status::Ok();
  uint8_t fixed[kFixed];
  TILTCAL_RETURN_IF_ERROR(ReadAt(offset + kRecordPrefixBytes, kFixed, fixed));
  uint32_t name_length = 0;
  std::memcpy(&name_length, fixed + 28, 4);
  if (name_length > kMaxCompressionName || kFixed + name_length + 8 > room) return Status::Ok();
  uint8_t records_size_bytes[8];
  TILTCAL_RETURN_IF_ERROR(
      ReadAt(offset + kRecordPrefixBytes + kFixed + name_length, 8, records_size_bytes));
  const uint64_t records_size = LoadU64(records_size_bytes);
  if (records_size > room - kFixed - name_length - 8) return Status::Ok();
  const uint64_t by_fields = kFixed + name_length + 8 + records_size;
  bool chains = false;
  TILTCAL_RETURN_IF_ERROR(ChainsToDataEnd(offset + kRecordPrefixBytes + by_fields, &chains));
  if (chains) *length = by_fields;
  return Status::Ok();
}

Status McapReader::ChainsToDataEnd(uint64_t offset, bool* chains) {
  *chains = false;
  std::vector<uint64_t> visited;
  for (uint64_t p = offset;;) {
    if (p == data_end_) {
      *chains = true;
      break;
    }
    if (p + kRecordPrefixBytes > data_end_ || dead_offsets_.count(p) > 0) break;
    uint8_t prefix[kRecordPrefixBytes];
    TILTCAL_RETURN_IF_ERROR(ReadAt(p, kRecordPrefixBytes, prefix));
    const uint64_t length = LoadU64(prefix + 1);
    const uint64_t room = data_end_ - p - kRecordPrefixBytes;
    if (!CanStartRecord(prefix[0]) || length > room) break;
    visited.push_back(p);
    if (prefix[0] == kDataEnd) {
      *chains = length == room;
      break;
    }
    p += kRecordPrefixBytes + length;
  }
  // Every offset of a failed chain fails the same way: never followed again.
  if (!*chains) dead_offsets_.insert(visited.begin(), visited.end());
  return Status::Ok();
}

}  // namespace tiltcal::mcap
