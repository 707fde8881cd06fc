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

bool McapReader::ChannelSelected(const Channel* channel,
                                 const bag::MessageSelection& selection) {
  return channel != nullptr &&
         (selection.topics.empty() ||
          std::find(selection.topics.begin(), selection.topics.end(), channel->topic) !=
              selection.topics.end());
}

Status McapReader::ReadMessages(const bag::MessageSelection& selection,
                                const std::function<Status(const bag::Message&)>& fn) {
  for (size_t id = 0; id < channels_.size(); ++id) {
    const Channel* c = channels_[id].get();
    if (!ChannelSelected(c, selection)) continue;
    if (c->message_encoding != "ros1" && c->message_encoding != "cdr") {
      return Status::Error(path_ + ": channel " + std::to_string(id) + " (topic '" + c->topic +
                           "') has message encoding '" + c->message_encoding +
                           "'; only cdr (ROS 2) and ros1 are read");
    }
  }
  return ReadMessageRecords(selection, Order::kLogTime,
                            [&fn](const bag::Message& m, const MessageRecord&) { return fn(m); });
}

std::vector<const McapReader::Entry*> McapReader::SelectedEntries(
    const bag::MessageSelection& selection, Order order) const {
  std::vector<bool> selected(channels_.size(), false);
  for (size_t id = 0; id < channels_.size(); ++id) {
    selected[id] = ChannelSelected(channels_[id].get(), selection);
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
  return items;
}

Status McapReader::ReadMessageRecord(const Entry& e, std::vector<uint8_t>* record,
                                     MessageRecord* message, uint64_t* where) {
  const uint8_t* data = nullptr;
  size_t size = 0;
  *where = e.offset;
  if (e.chunk != kNoChunk) {
    const std::vector<uint8_t>* records = nullptr;
    TILTCAL_RETURN_IF_ERROR(LoadChunk(e.chunk, &records));
    *where = chunks_[e.chunk].offset;
    if (e.offset > records->size()) return Error(*where, "message offset past its chunk");
    data = records->data() + e.offset;
    size = records->size() - e.offset;
  } else {
    record->resize(kRecordPrefixBytes + kMessageFixedBytes);
    TILTCAL_RETURN_IF_ERROR(ReadAt(e.offset, kRecordPrefixBytes, record->data()));
    const uint64_t length = LoadU64(record->data() + 1);
    if (length > kMaxRecordBytes || length > file_size_ - e.offset - kRecordPrefixBytes) {
      return Error(*where, "Message record of " + std::to_string(length) +
                               " bytes runs past the end of the file");
    }
    record->resize(kRecordPrefixBytes + length);
    TILTCAL_RETURN_IF_ERROR(ReadAt(e.offset, record->size(), record->data()));
    data = record->data();
    size = record->size();
  }
  Status status = size < kRecordPrefixBytes || data[0] != kMessage ||
                          LoadU64(data + 1) > size - kRecordPrefixBytes
                      ? Status::Error("no Message record at offset " + std::to_string(e.offset))
                      : ParseMessage(data + kRecordPrefixBytes, LoadU64(data + 1), message);
  if (!status.ok()) return Error(*where, status.message());
  if (message->channel_id != e.channel || static_cast<int64_t>(message->log_time) != e.time_ns) {
    return Error(*where, "the message index does not match the Message record at offset " +
                             std::to_string(e.offset));
  }
  return Status::Ok();
}

Status McapReader::ReadMessageRecords(
    const bag::MessageSelection& selection, Order order,
    const std::function<Status(const bag::Message&, const MessageRecord&)>& fn) {
  std::vector<bag::Encoding> encodings(channels_.size(), bag::Encoding::kCdr);
  for (size_t id = 0; id < channels_.size(); ++id) {
    const Channel* c = channels_[id].get();
    if (c != nullptr && c->message_encoding == "ros1") encodings[id] = bag::Encoding::kRos1;
  }
  bag::Message m;
  m.file = nullptr;  // one file: the caller names it
  std::vector<uint8_t> record;
  for (const Entry* e : SelectedEntries(selection, order)) {
    MessageRecord message;
    uint64_t where = 0;
    TILTCAL_RETURN_IF_ERROR(ReadMessageRecord(*e, &record, &message, &where));
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
