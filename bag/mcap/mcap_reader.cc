#include "bag/mcap/mcap_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <map>

#include "common/io/input_file.h"

namespace tiltcal::mcap {

namespace {

constexpr char kChunkPosition[] = "chunk at byte";
constexpr char kRecordPosition[] = "record at byte";
// No record of a sane recording is this large; refuse before allocating.
constexpr uint64_t kMaxRecordBytes = uint64_t{4} << 30;

uint64_t LoadU64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

std::string OpcodeName(uint8_t opcode) {
  switch (opcode) {
    case kHeader: return "Header";
    case kFooter: return "Footer";
    case kSchema: return "Schema";
    case kChannel: return "Channel";
    case kMessage: return "Message";
    case kChunk: return "Chunk";
    case kMessageIndex: return "MessageIndex";
    case kChunkIndex: return "ChunkIndex";
    case kDataEnd: return "DataEnd";
    default: return "opcode " + std::to_string(opcode);
  }
}

// Opcodes a record of the data section may have when looking for where the
// records resume after a damaged one: the known records and the private
// ones (0x80 and up).
bool CanStartRecord(uint8_t opcode) {
  return (opcode >= kSchema && opcode <= kDataEnd) || opcode >= 0x80;
}

// More damaged records than this: not a recording worth salvaging.
constexpr int kMaxDamagedRecords = 100;

}  // namespace

McapReader::McapReader(uint64_t max_chunk_bytes)
    : max_chunk_bytes_(max_chunk_bytes), decompressor_(max_chunk_bytes) {}

McapReader::~McapReader() {
  if (fd_ >= 0) ::close(fd_);
}

Status McapReader::Error(uint64_t offset, const std::string& what) const {
  return Status::Error(path_ + ": byte " + std::to_string(offset) + ": " + what);
}

Status McapReader::ReadAt(uint64_t offset, uint64_t size, void* dst) const {
  if (offset > file_size_ || size > file_size_ - offset) {
    return Error(offset, std::to_string(size) + " bytes run past the end of the file (" +
                             std::to_string(file_size_) + " bytes)");
  }
  auto* out = static_cast<uint8_t*>(dst);
  while (size > 0) {
    const ssize_t n = ::pread(fd_, out, size, static_cast<off_t>(offset));
    if (n <= 0) return Error(offset, std::string("read failed: ") + std::strerror(errno));
    out += n;
    offset += static_cast<uint64_t>(n);
    size -= static_cast<uint64_t>(n);
  }
  return Status::Ok();
}

Status McapReader::ReadRecord(uint64_t offset, uint64_t end, uint8_t* opcode,
                              std::vector<uint8_t>* content) const {
  uint8_t prefix[kRecordPrefixBytes];
  if (offset + kRecordPrefixBytes > end) return Error(offset, "record runs past its section");
  TILTCAL_RETURN_IF_ERROR(ReadAt(offset, kRecordPrefixBytes, prefix));
  *opcode = prefix[0];
  const uint64_t length = LoadU64(prefix + 1);
  if (length > kMaxRecordBytes || length > end - offset - kRecordPrefixBytes) {
    return Error(offset, OpcodeName(*opcode) + " record of " + std::to_string(length) +
                             " bytes runs past its section");
  }
  content->resize(length);
  return ReadAt(offset + kRecordPrefixBytes, length, content->data());
}

Status McapReader::Open(const std::string& path, SummaryUse summary_use) {
  path_ = path;
  TILTCAL_RETURN_IF_ERROR(OpenInputFile(path, &fd_, &file_size_));
  TILTCAL_RETURN_IF_ERROR(ReadHeader());
  TILTCAL_RETURN_IF_ERROR(ReadFooter());
  bool usable = false;
  if (summary_use == SummaryUse::kIfUsable) TILTCAL_RETURN_IF_ERROR(ReadSummary(&usable));
  if (!usable) {
    indexed_ = false;
    schema_names_.clear();
    channels_.clear();
    chunks_.clear();
    entries_.clear();
  }
  TILTCAL_RETURN_IF_ERROR(WalkDataSection());
  FinishTopics();
  return Status::Ok();
}

Status McapReader::ReadHeader() {
  uint8_t magic[sizeof(kMagic)] = {};
  if (file_size_ >= sizeof(kMagic)) TILTCAL_RETURN_IF_ERROR(ReadAt(0, sizeof(kMagic), magic));
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0) {
    return Error(0, "not an MCAP file (it does not start with the MCAP magic)");
  }
  uint8_t opcode = 0;
  std::vector<uint8_t> content;
  TILTCAL_RETURN_IF_ERROR(ReadRecord(sizeof(kMagic), file_size_, &opcode, &content));
  if (opcode != kHeader) {
    return Error(sizeof(kMagic), "the first record is " + OpcodeName(opcode) + ", not Header");
  }
  FieldReader f(content.data(), content.size());
  Status status = f.String("header profile", &profile_);
  if (!status.ok()) return Error(sizeof(kMagic), status.message());
  header_end_ = sizeof(kMagic) + kRecordPrefixBytes + content.size();
  return Status::Ok();
}

Status McapReader::ReadFooter() {
  data_end_ = file_size_;
  if (file_size_ < 2 * sizeof(kMagic) + kFooterBytes) return Status::Ok();
  uint8_t tail[kFooterBytes + sizeof(kMagic)];
  const uint64_t footer = file_size_ - sizeof(tail);
  TILTCAL_RETURN_IF_ERROR(ReadAt(footer, sizeof(tail), tail));
  if (std::memcmp(tail + kFooterBytes, kMagic, sizeof(kMagic)) != 0) return Status::Ok();
  if (tail[0] != kFooter || LoadU64(tail + 1) != 20) {
    return Error(footer, "the file ends with the MCAP magic but not after a Footer record");
  }
  summary_start_ = LoadU64(tail + kRecordPrefixBytes);
  if (summary_start_ != 0 && (summary_start_ < header_end_ || summary_start_ > footer)) {
    return Error(footer, "Footer summary_start " + std::to_string(summary_start_) +
                             " is outside the file");
  }
  if (footer < header_end_) return Error(footer, "the Footer overlaps the Header");
  complete_ = true;
  data_end_ = summary_start_ != 0 ? summary_start_ : footer;
  return Status::Ok();
}

Status McapReader::ReadSummary(bool* usable) {
  *usable = false;
  if (!complete_ || summary_start_ == 0) return Status::Ok();
  const uint64_t footer = file_size_ - kFooterBytes - sizeof(kMagic);
  const uint64_t summary_start = summary_start_;
  std::vector<ChunkIndexRecord> chunk_indexes;
  std::vector<uint8_t> content;
  for (uint64_t offset = summary_start; offset < footer;) {
    uint8_t opcode = 0;
    TILTCAL_RETURN_IF_ERROR(ReadRecord(offset, footer, &opcode, &content));
    if (opcode == kSchema || opcode == kChannel) {
      TILTCAL_RETURN_IF_ERROR(AddSchemaOrChannel(opcode, content.data(), content.size(), offset));
    } else if (opcode == kChunkIndex) {
      chunk_indexes.emplace_back();
      Status status = ParseChunkIndex(content.data(), content.size(), &chunk_indexes.back());
      if (!status.ok()) return Error(offset, status.message());
    }
    offset += kRecordPrefixBytes + content.size();
  }
  // Without chunk indexes, with chunks whose message indexes are not
  // listed, or with channels the summary does not describe, the data
  // section must be scanned.
  if (chunk_indexes.empty()) return Status::Ok();
  for (const ChunkIndexRecord& index : chunk_indexes) {
    if (index.message_index_offsets.empty()) return Status::Ok();
    for (const auto& [channel, offset] : index.message_index_offsets) {
      if (channel >= channels_.size() || channels_[channel] == nullptr) return Status::Ok();
    }
  }
  std::sort(chunk_indexes.begin(), chunk_indexes.end(),
            [](const ChunkIndexRecord& a, const ChunkIndexRecord& b) {
              return a.chunk_start_offset < b.chunk_start_offset;
            });
  for (const ChunkIndexRecord& index : chunk_indexes) {
    TILTCAL_RETURN_IF_ERROR(IndexChunkFromSummary(index));
  }
  *usable = true;
  return Status::Ok();
}

Status McapReader::IndexChunkFromSummary(const ChunkIndexRecord& index) {
  const auto chunk = static_cast<uint32_t>(chunks_.size());
  if (index.chunk_start_offset > file_size_ ||
      index.chunk_length > file_size_ - index.chunk_start_offset) {
    return Error(index.chunk_start_offset, "ChunkIndex points to a chunk past the end of the file");
  }
  chunks_.push_back({index.chunk_start_offset, index.chunk_length,
                     std::min(index.uncompressed_size, max_chunk_bytes_)});
  std::vector<uint8_t> content;
  for (const auto& [channel, offset] : index.message_index_offsets) {
    uint8_t opcode = 0;
    TILTCAL_RETURN_IF_ERROR(ReadRecord(offset, file_size_, &opcode, &content));
    if (opcode != kMessageIndex) {
      return Error(offset, "ChunkIndex points to a " + OpcodeName(opcode) +
                               " record, not a MessageIndex");
    }
    uint16_t channel_id = 0;
    Status status = ParseMessageIndex(content.data(), content.size(), &channel_id,
                                      [&](uint64_t time, uint64_t message_offset) {
                                        entries_.push_back({static_cast<int64_t>(time),
                                                            message_offset, chunk, channel_id});
                                      });
    if (!status.ok()) return Error(offset, status.message());
    if (channel_id != channel) {
      return Error(offset, "MessageIndex of channel " + std::to_string(channel_id) +
                               " listed for channel " + std::to_string(channel));
    }
  }
  return Status::Ok();
}

Status McapReader::WalkDataSection() {
  // The chunks the summary listed (sorted by offset): not read again.
  const size_t listed = chunks_.size();
  const bool summary = indexed_;
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
  uint64_t offset = header_end_;
  while (true) {
    if (complete_ && offset == data_end_) break;  // no DataEnd record: tolerated
    std::string damage;  // why the record at `offset` is damaged
    uint8_t opcode = 0;
    uint64_t length = 0;
    if (offset + kRecordPrefixBytes > data_end_) {
      if (!complete_) {
        salvage_note_ = "the recording ends at byte " + std::to_string(file_size_) +
                        " without its DataEnd record";
        break;
      }
      damage = "the data section ends at byte " + std::to_string(data_end_) +
               " inside its 9-byte prefix";
    } else {
      uint8_t prefix[kRecordPrefixBytes];
      TILTCAL_RETURN_IF_ERROR(ReadAt(offset, kRecordPrefixBytes, prefix));
      opcode = prefix[0];
      length = LoadU64(prefix + 1);
      const uint64_t room = data_end_ - offset - kRecordPrefixBytes;
      if (!complete_ && (opcode == kDataEnd || opcode == kFooter)) break;
      if (opcode == kDataEnd && length == room) break;
      if (length > room) {
        if (!complete_) {
          salvage_note_ = "the recording ends inside the " + OpcodeName(opcode) +
                          " record at byte " + std::to_string(offset) + " (" +
                          std::to_string(file_size_) + " bytes): what follows it is lost";
          break;
        }
        damage = "length " + std::to_string(length) + " runs past the end of the data section at byte " +
                 std::to_string(data_end_);
      } else if (opcode == kDataEnd) {
        damage = "it ends at byte " + std::to_string(offset + kRecordPrefixBytes + length) +
                 ", not at the end of the data section (byte " + std::to_string(data_end_) + ")";
      } else if (opcode == 0 || opcode == kHeader || opcode == kFooter) {
        damage = "no " + OpcodeName(opcode) + " record belongs in the data section";
      }
    }
    if (!damage.empty() && opcode == kChunk && offset + kRecordPrefixBytes <= data_end_) {
      // Only the length is damaged when the chunk's own fields give one from
      // which the records after it chain onto the end of the data section.
      uint64_t by_fields = 0;
      TILTCAL_RETURN_IF_ERROR(ChunkLengthByItsFields(offset, &by_fields));
      if (by_fields != 0 && by_fields != length) {
        warnings_.push_back(DamagedChunkLength(offset, length, by_fields));
        length = by_fields;
        damage.clear();
      }
    }
    const size_t entries_before = entries_.size();
    const size_t chunks_before = chunks_.size();
    if (damage.empty() && opcode == kChunk) {
      const bool in_summary =
          std::binary_search(chunks_.begin(), chunks_.begin() + static_cast<long>(listed),
                             Chunk{offset, 0, 0},
                             [](const Chunk& a, const Chunk& b) { return a.offset < b.offset; });
      if (!in_summary) {
        if (length > kMaxRecordBytes) {
          return Error(offset, "Chunk record of " + std::to_string(length) + " bytes");
        }
        content.resize(length);
        TILTCAL_RETURN_IF_ERROR(ReadAt(offset + kRecordPrefixBytes, length, content.data()));
        ChunkRecord chunk;
        Status status = ParseChunk(content.data(), content.size(), &chunk);
        if (!status.ok() && !complete_) return Error(offset, "Chunk: " + status.message());
        if (!status.ok()) {
          damage = status.message();
        } else {
          const auto index = static_cast<uint32_t>(chunks_.size());
          chunks_.push_back({offset, kRecordPrefixBytes + length, chunk.uncompressed_size});
          // Decompressed into the cache: the first ReadMessages() finds it there.
          std::vector<uint8_t>* records = CacheSlot(index, chunk.uncompressed_size);
          status = decompressor_.Decompress(chunk, records);
          if (!status.ok()) return Error(offset, "Chunk: " + status.message());
          if (!chunk.compression.empty()) ++chunks_decompressed_;
          cached_bytes_ += records->size();
          TILTCAL_RETURN_IF_ERROR(IndexRecords(records->data(), records->size(), index, offset));
          if (summary) {
            if (unlisted_chunks++ == 0) first_unlisted = offset;
            unlisted_entries += entries_.size() - entries_before;
          }
        }
      }
    } else if (damage.empty() &&
               (opcode == kSchema || opcode == kChannel || opcode == kMessage)) {
      content.resize(kRecordPrefixBytes + length);
      TILTCAL_RETURN_IF_ERROR(ReadAt(offset, content.size(), content.data()));
      Status status = IndexRecords(content.data(), content.size(), kNoChunk, offset);
      if (!status.ok() && !complete_) return status;
      if (!status.ok()) damage = OpcodeName(opcode) + " does not parse";
    }
    if (damage.empty()) {
      last = {true, offset, opcode, entries_before, chunks_before};
      offset += kRecordPrefixBytes + length;
      continue;
    }
    // A damaged record. When it is no record at all (an opcode no record
    // starts with), the length of the record before it is the damaged
    // one: that record and what it gave are dropped.
    if (!CanStartRecord(opcode) && last.valid && last.opcode == kChunk) {
      // The chunk before it was read whole by its own fields; only its
      // length overshoots.
      uint64_t by_fields = 0;
      TILTCAL_RETURN_IF_ERROR(ChunkLengthByItsFields(last.offset, &by_fields));
      const uint64_t resume = last.offset + kRecordPrefixBytes + by_fields;
      if (by_fields != 0 && resume != offset) {
        warnings_.push_back(DamagedChunkLength(
            last.offset, offset - last.offset - kRecordPrefixBytes, by_fields));
        for (size_t c = last.chunks; c < chunks_.size(); ++c) {
          chunks_[c].length = kRecordPrefixBytes + by_fields;
        }
        last.valid = false;
        offset = resume;
        continue;
      }
    }
    if (++damaged > kMaxDamagedRecords) {
      return Error(offset, "more than " + std::to_string(kMaxDamagedRecords) +
                               " damaged records; the last: " + damage);
    }
    std::string what = "the " + OpcodeName(opcode) + " record at byte " + std::to_string(offset) +
                       " (" + damage + ")";
    uint64_t skip_from = offset;
    size_t dropped = 0;
    if (!CanStartRecord(opcode) && last.valid) {
      what = "the " + OpcodeName(last.opcode) + " record at byte " + std::to_string(last.offset) +
             " (its length leads to byte " + std::to_string(offset) +
             ", where no record starts)";
      skip_from = last.offset;
      dropped = entries_.size() - last.entries;
      entries_.resize(last.entries);
      for (size_t c = last.chunks; c < chunks_.size(); ++c) {
        cache_.remove_if([&](const CachedChunk& cached) { return cached.chunk == c; });
      }
      if (chunks_.size() > last.chunks) chunks_.resize(last.chunks);
    } else {
      entries_.resize(entries_before);
      chunks_.resize(chunks_before);
    }
    cached_bytes_ = 0;
    for (const CachedChunk& cached : cache_) cached_bytes_ += cached.records.size();
    uint64_t resume = data_end_;
    TILTCAL_RETURN_IF_ERROR(FindResumeOffset(skip_from + 1, listed, &resume));
    skipped_bytes += resume - skip_from;
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
    last.valid = false;
    offset = resume;
  }
  // Messages of channels no Channel record defines (their Channel record
  // was in a damaged record) cannot be given a topic.
  const auto defined = [this](const Entry& e) {
    return e.channel < channels_.size() && channels_[e.channel] != nullptr;
  };
  const auto without_channel = static_cast<size_t>(
      std::count_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return !defined(e); }));
  if (without_channel > 0) {
    entries_.erase(std::remove_if(entries_.begin(), entries_.end(),
                                  [&](const Entry& e) { return !defined(e); }),
                   entries_.end());
    warnings_.push_back(path_ + ": " + std::to_string(without_channel) +
                        " messages on channels that no Channel record defines left out (their "
                        "topic is unknown)");
  }
  if (damaged > 0) {
    warnings_.push_back(path_ + ": " + std::to_string(damaged) + " damaged record(s), " +
                        std::to_string(skipped_bytes) + " bytes skipped; " +
                        std::to_string(entries_.size()) +
                        " messages read from the rest of the file");
  }
  if (unlisted_chunks > 0) {
    warnings_.push_back(path_ + ": the summary disagrees with the data section: it lists " +
                        std::to_string(listed) + " chunks, the data section holds " +
                        std::to_string(listed + unlisted_chunks) + "; the " +
                        std::to_string(unlisted_chunks) + " chunk(s) it omits (the first at byte " +
                        std::to_string(first_unlisted) + ", " +
                        std::to_string(unlisted_entries) +
                        " messages) were read from the data section");
  }
  return Status::Ok();
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

Status McapReader::IndexRecords(const uint8_t* data, size_t size, uint32_t chunk,
                                uint64_t base) {
  for (size_t pos = 0; pos < size;) {
    const uint64_t where = chunk == kNoChunk ? base + pos : base;
    const std::string inside =
        chunk == kNoChunk ? "" : " (offset " + std::to_string(pos) + " in the chunk)";
    if (size - pos < kRecordPrefixBytes) return Error(where, "truncated record" + inside);
    const uint8_t opcode = data[pos];
    const uint64_t length = LoadU64(data + pos + 1);
    if (length > size - pos - kRecordPrefixBytes) {
      return Error(where, OpcodeName(opcode) + " record runs past its chunk" + inside);
    }
    const uint8_t* content = data + pos + kRecordPrefixBytes;
    if (opcode == kSchema || opcode == kChannel) {
      TILTCAL_RETURN_IF_ERROR(AddSchemaOrChannel(opcode, content, length, where));
    } else if (opcode == kMessage) {
      MessageRecord m;
      Status status = ParseMessage(content, length, &m);
      if (!status.ok()) return Error(where, status.message() + inside);
      entries_.push_back({static_cast<int64_t>(m.log_time),
                          chunk == kNoChunk ? base + pos : pos, chunk, m.channel_id});
    }
    pos += kRecordPrefixBytes + length;
  }
  return Status::Ok();
}

Status McapReader::AddSchemaOrChannel(uint8_t opcode, const uint8_t* content, size_t size,
                                      uint64_t offset) {
  if (opcode == kSchema) {
    SchemaRecord s;
    Status status = ParseSchema(content, size, &s);
    if (!status.ok()) return Error(offset, status.message());
    if (schema_names_.size() <= s.id) schema_names_.resize(s.id + 1u);
    schema_names_[s.id] = s.name;
    return Status::Ok();
  }
  ChannelRecord c;
  Status status = ParseChannel(content, size, &c);
  if (!status.ok()) return Error(offset, status.message());
  if (channels_.size() <= c.id) channels_.resize(c.id + 1u);
  if (channels_[c.id] == nullptr) channels_[c.id] = std::make_unique<Channel>();
  channels_[c.id]->topic = c.topic;
  channels_[c.id]->message_encoding = c.message_encoding;
  channels_[c.id]->schema_id = c.schema_id;
  return Status::Ok();
}

void McapReader::FinishTopics() {
  std::map<std::string, bag::TopicInfo> topics;
  for (const auto& channel : channels_) {
    if (channel == nullptr) continue;
    const std::string type =
        channel->schema_id < schema_names_.size() ? schema_names_[channel->schema_id] : "";
    topics.emplace(channel->topic, bag::TopicInfo{channel->topic, type, 0});
  }
  for (const Entry& e : entries_) {
    if (e.channel < channels_.size() && channels_[e.channel] != nullptr) {
      ++topics[channels_[e.channel]->topic].message_count;
    }
    start_ns_ = std::min(start_ns_, e.time_ns);
    end_ns_ = std::max(end_ns_, e.time_ns);
  }
  topics_.clear();
  for (auto& [name, topic] : topics) topics_.push_back(topic);
}

bool McapReader::TimeRange(int64_t* start_ns, int64_t* end_ns) const {
  if (entries_.empty()) return false;
  *start_ns = start_ns_;
  *end_ns = end_ns_;
  return true;
}

Status McapReader::DecompressChunkAt(uint64_t offset, uint64_t length,
                                     std::vector<uint8_t>* records) {
  // The record's length is the summary's or the data section walk's (which
  // may have found the prefix's length damaged).
  uint8_t opcode = 0;
  TILTCAL_RETURN_IF_ERROR(ReadAt(offset, 1, &opcode));
  if (opcode != kChunk) return Error(offset, OpcodeName(opcode) + " record where a Chunk is");
  if (length < kRecordPrefixBytes || length - kRecordPrefixBytes > kMaxRecordBytes) {
    return Error(offset, "Chunk record of " + std::to_string(length) + " bytes");
  }
  std::vector<uint8_t> content(length - kRecordPrefixBytes);
  TILTCAL_RETURN_IF_ERROR(ReadAt(offset + kRecordPrefixBytes, content.size(), content.data()));
  ChunkRecord chunk;
  Status status = ParseChunk(content.data(), content.size(), &chunk);
  if (status.ok()) status = decompressor_.Decompress(chunk, records);
  if (!status.ok()) return Error(offset, "Chunk: " + status.message());
  if (!chunk.compression.empty()) ++chunks_decompressed_;
  return Status::Ok();
}

std::vector<uint8_t>* McapReader::CacheSlot(uint32_t chunk, uint64_t bytes) {
  // Evict the least recently used chunks until the new one fits the count
  // and the bytes; the last evicted buffer is reused.
  std::vector<uint8_t> reuse;
  while (!cache_.empty() &&
         (cache_.size() >= cache_size_ || cached_bytes_ + bytes > max_chunk_bytes_)) {
    cached_bytes_ -= cache_.back().records.size();
    reuse.swap(cache_.back().records);
    cache_.pop_back();
  }
  cache_.emplace_front();
  cache_.front().chunk = chunk;
  cache_.front().records.swap(reuse);
  cache_.front().records.clear();
  return &cache_.front().records;
}

Status McapReader::LoadChunk(uint32_t chunk, const std::vector<uint8_t>** records) {
  for (auto it = cache_.begin(); it != cache_.end(); ++it) {
    if (it->chunk == chunk) {
      cache_.splice(cache_.begin(), cache_, it);
      *records = &cache_.front().records;
      return Status::Ok();
    }
  }
  std::vector<uint8_t>* slot = CacheSlot(chunk, chunks_[chunk].uncompressed_size);
  Status status = DecompressChunkAt(chunks_[chunk].offset, chunks_[chunk].length, slot);
  if (!status.ok()) {
    cache_.pop_front();
    return status;
  }
  cached_bytes_ += slot->size();
  *records = slot;
  return Status::Ok();
}

Status McapReader::ChunkCompressions(std::map<std::string, int64_t>* compressions) const {
  compressions->clear();
  // Chunk content: start u64, end u64, uncompressed_size u64, crc u32, then
  // the compression string (u32 length + bytes).
  constexpr uint64_t kCompressionAt = kRecordPrefixBytes + 8 + 8 + 8 + 4;
  for (const Chunk& chunk : chunks_) {
    uint32_t length = 0;
    if (chunk.length < kCompressionAt + 4) return Error(chunk.offset, "Chunk record too short");
    TILTCAL_RETURN_IF_ERROR(ReadAt(chunk.offset + kCompressionAt, 4, &length));
    if (length > chunk.length - kCompressionAt - 4) {
      return Error(chunk.offset, "Chunk compression runs past its record");
    }
    std::string name(length, '\0');
    TILTCAL_RETURN_IF_ERROR(ReadAt(chunk.offset + kCompressionAt + 4, length, name.data()));
    ++(*compressions)[name.empty() ? "none" : name];
  }
  return Status::Ok();
}

Status McapReader::ReadMessages(const bag::MessageSelection& selection,
                                const std::function<Status(const bag::Message&)>& fn) {
  for (size_t id = 0; id < channels_.size(); ++id) {
    const Channel* c = channels_[id].get();
    if (c == nullptr || (!selection.topics.empty() &&
                         std::find(selection.topics.begin(), selection.topics.end(), c->topic) ==
                             selection.topics.end())) {
      continue;
    }
    if (c->message_encoding != "ros1" && c->message_encoding != "cdr") {
      return Status::Error(path_ + ": channel " + std::to_string(id) + " (topic '" + c->topic +
                           "') has message encoding '" + c->message_encoding +
                           "'; only cdr (ROS 2) and ros1 are read");
    }
  }
  return ReadMessageRecords(selection, Order::kLogTime,
                            [&fn](const bag::Message& m, const MessageRecord&) { return fn(m); });
}

Status McapReader::ReadMessageRecords(
    const bag::MessageSelection& selection, Order order,
    const std::function<Status(const bag::Message&, const MessageRecord&)>& fn) {
  std::vector<bool> selected(channels_.size(), false);
  std::vector<bag::Encoding> encodings(channels_.size(), bag::Encoding::kCdr);
  for (size_t id = 0; id < channels_.size(); ++id) {
    const Channel* c = channels_[id].get();
    if (c == nullptr || (!selection.topics.empty() &&
                         std::find(selection.topics.begin(), selection.topics.end(), c->topic) ==
                             selection.topics.end())) {
      continue;
    }
    if (c->message_encoding == "ros1") encodings[id] = bag::Encoding::kRos1;
    selected[id] = true;
  }
  std::vector<const Entry*> items;
  for (const Entry& e : entries_) {
    if (e.channel < selected.size() && selected[e.channel] && e.time_ns >= selection.start_ns &&
        e.time_ns < selection.end_ns) {
      items.push_back(&e);
    }
  }
  // File order: (file position of the chunk or record, offset in the
  // chunk); log-time order: (log time, file order).
  auto file_position = [this](const Entry* e) {
    return e->chunk == kNoChunk ? e->offset : chunks_[e->chunk].offset;
  };
  auto file_order = [&](const Entry* a, const Entry* b) {
    if (file_position(a) != file_position(b)) return file_position(a) < file_position(b);
    return a->offset < b->offset;
  };
  if (order == Order::kFile) {
    std::sort(items.begin(), items.end(), file_order);
  } else {
    std::sort(items.begin(), items.end(), [&](const Entry* a, const Entry* b) {
      if (a->time_ns != b->time_ns) return a->time_ns < b->time_ns;
      return file_order(a, b);
    });
  }
  bag::Message m;
  m.file = nullptr;  // one file: the caller names it
  std::vector<uint8_t> record;
  for (const Entry* e : items) {
    const uint8_t* data = nullptr;
    size_t size = 0;
    uint64_t where = e->offset;
    if (e->chunk != kNoChunk) {
      const std::vector<uint8_t>* records = nullptr;
      TILTCAL_RETURN_IF_ERROR(LoadChunk(e->chunk, &records));
      where = chunks_[e->chunk].offset;
      if (e->offset > records->size()) return Error(where, "message offset past its chunk");
      data = records->data() + e->offset;
      size = records->size() - e->offset;
    } else {
      record.resize(kRecordPrefixBytes + kMessageFixedBytes);
      TILTCAL_RETURN_IF_ERROR(ReadAt(e->offset, kRecordPrefixBytes, record.data()));
      const uint64_t length = LoadU64(record.data() + 1);
      if (length > kMaxRecordBytes || length > file_size_ - e->offset - kRecordPrefixBytes) {
        return Error(where, "Message record of " + std::to_string(length) +
                                " bytes runs past the end of the file");
      }
      record.resize(kRecordPrefixBytes + length);
      TILTCAL_RETURN_IF_ERROR(ReadAt(e->offset, record.size(), record.data()));
      data = record.data();
      size = record.size();
    }
    MessageRecord message;
    Status status = size < kRecordPrefixBytes || data[0] != kMessage ||
                            LoadU64(data + 1) > size - kRecordPrefixBytes
                        ? Status::Error("no Message record at offset " + std::to_string(e->offset))
                        : ParseMessage(data + kRecordPrefixBytes, LoadU64(data + 1), &message);
    if (!status.ok()) return Error(where, status.message());
    if (message.channel_id != e->channel || static_cast<int64_t>(message.log_time) != e->time_ns) {
      return Error(where, "the message index does not match the Message record at offset " +
                              std::to_string(e->offset));
    }
    m.topic = &channels_[e->channel]->topic;
    m.encoding = encodings[e->channel];
    m.time_ns = e->time_ns;
    m.position_name = e->chunk != kNoChunk ? kChunkPosition : kRecordPosition;
    m.position = where;
    m.data = message.data;
    m.size = message.size;
    TILTCAL_RETURN_IF_ERROR(fn(m, message));
    ++m.sequence;
  }
  // The decompressed chunks are freed once read (one file of a sequence
  // split over many stays open while the others are read).
  cache_.clear();
  cached_bytes_ = 0;
  return Status::Ok();
}

}  // namespace tiltcal::mcap
