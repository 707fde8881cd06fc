#include "bag/ros1/bag_reader.h"

#include <algorithm>
#include <memory>
#include <set>
#include <tuple>

#include "bag/ros1/bag_salvage.h"
#include "bag/ros1/chunk_cache.h"

namespace tiltcal::ros1 {
namespace {


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


BagReader::BagReader() = default;
BagReader::~BagReader() = default;

Status BagReader::Open(const std::string& path) {
  TILTCAL_RETURN_IF_ERROR(file_.Open(path));
  if (file_.size() == 0) return Status::Error(path + ": empty file (0 bytes), not a ROS bag");

  TILTCAL_RETURN_IF_ERROR(CheckVersionLine());

  // Bag header record.
  const uint64_t header_pos = kVersionLine.size();
  std::string buffer;
  RecordHeader header;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  TILTCAL_RETURN_IF_ERROR(file_.ReadRecordHeaderAt(header_pos, &buffer, &header, &data_pos, &data_len));
  uint64_t index_pos = 0;
  uint32_t conn_count = 0;
  uint32_t chunk_count = 0;
  Status status = RequireOp(header, Op::kBagHeader, "the bag header record");
  if (status.ok()) status = header.GetU64("index_pos", &index_pos);
  if (status.ok()) status = header.GetU32("conn_count", &conn_count);
  if (status.ok()) status = header.GetU32("chunk_count", &chunk_count);
  if (!status.ok()) return file_.Error(header_pos, "bag header: " + status.message());
  if (const std::string_view* encryptor = header.Find("encryptor");
      encryptor != nullptr && !encryptor->empty()) {
    return Status::Error(path + ": encrypted bag (encryptor=" + std::string(*encryptor) +
                         ") is not supported");
  }
  const uint64_t first_record_pos = data_pos + data_len;
  if (index_pos == 0) {
    indexed_ = false;
    SalvageResult salvage;
    const Status scanned = SalvageUnindexedBag(file_, first_record_pos, &decompressor_, &stats_,
                                               &index_, &salvage);
    num_salvaged_ = salvage.num_messages;
    salvage_note_ = std::move(salvage.note);
    return scanned;
  }
  if (index_pos < first_record_pos) {
    return file_.Error(header_pos, "bag header: index_pos " + std::to_string(index_pos) +
                                 " points inside the bag header");
  }
  return ReadIndexed(index_pos, conn_count, chunk_count);
}

Status BagReader::CheckVersionLine() const {
  char magic[16] = {};
  const size_t magic_size = static_cast<size_t>(std::min<uint64_t>(file_.size(), sizeof(magic)));
  TILTCAL_RETURN_IF_ERROR(file_.ReadAt(0, magic_size, magic));
  const std::string_view head(magic, magic_size);
  if (head.substr(0, kVersionLine.size()) != kVersionLine) {
    if (head.rfind("#ROSRECORD V1.2", 0) == 0 || head.rfind("#ROSBAG V1.", 0) == 0) {
      return Status::Error(file_.path() + ": ROS bag format V1.2 is not supported (only V2.0, "
                                  "written by ROS since 2010)");
    }
    if (head.rfind("#ROSBAG V", 0) == 0 || head.rfind("#ROSRECORD V", 0) == 0) {
      return Status::Error(file_.path() + ": unsupported ROS bag version '" +
                           std::string(head.substr(0, head.find('\n'))) + "' (only V2.0)");
    }
    if (head.rfind("SQLite format 3", 0) == 0) {
      return Status::Error(file_.path() + ": a ROS 2 sqlite3 bag (.db3); only ROS1 .bag files are "
                                  "supported");
    }
    if (head.rfind("\x89MCAP", 0) == 0) {
      return Status::Error(file_.path() + ": an MCAP file; only ROS1 .bag files are supported");
    }
    return Status::Error(file_.path() + ": not a ROS1 bag: wrong magic (expected \"#ROSBAG V2.0\")");
  }
  return Status::Ok();
}

Status BagReader::ReadIndexed(uint64_t index_pos, uint32_t conn_count, uint32_t chunk_count) {
  if (index_pos > file_.size()) {
    return Status::Error(file_.path() + ": bag is truncated: its index at byte " +
                         std::to_string(index_pos) + " lies past the end of the file (" +
                         std::to_string(file_.size()) + " bytes)");
  }
  uint64_t pos = index_pos;
  TILTCAL_RETURN_IF_ERROR(ReadConnectionRecords(conn_count, &pos));
  TILTCAL_RETURN_IF_ERROR(ReadChunkInfos(chunk_count, pos));
  TILTCAL_RETURN_IF_ERROR(ReadChunkHeaders());
  std::sort(index_.chunks.begin(), index_.chunks.end(),
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
    TILTCAL_RETURN_IF_ERROR(file_.ReadRecordHeaderAt(*pos, &buffer, &header, &data_pos, &data_len));
    Status status = RequireOp(header, Op::kConnection,
                              "connection record " + std::to_string(i + 1) + " of " +
                                  std::to_string(conn_count));
    if (!status.ok()) return file_.Error(*pos, status.message());
    data.resize(data_len);
    TILTCAL_RETURN_IF_ERROR(file_.ReadAt(data_pos, data_len, data.data()));
    status = index_.AddConnection(header, reinterpret_cast<const uint8_t*>(data.data()),
                                  data.size(), /*entries_loaded=*/false);
    if (!status.ok()) return file_.Error(*pos, status.message());
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
    TILTCAL_RETURN_IF_ERROR(file_.ReadRecordHeaderAt(pos, &buffer, &header, &data_pos, &data_len));
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
    if (!status.ok()) return file_.Error(pos, status.message());
    data.resize(data_len);
    TILTCAL_RETURN_IF_ERROR(file_.ReadAt(data_pos, data_len, data.data()));
    uint64_t messages_in_chunk = 0;
    for (uint32_t k = 0; k < count; ++k) {
      const uint32_t conn = LoadU32Le(data.data() + 8 * k);
      const uint32_t messages = LoadU32Le(data.data() + 8 * k + 4);
      const int slot = index_.ConnectionSlot(conn);
      if (slot < 0) {
        return file_.Error(pos, "chunk info refers to unknown connection " + std::to_string(conn));
      }
      chunk.connection_counts.emplace_back(slot, messages);
      index_.message_counts[slot] += messages;
      messages_in_chunk += messages;
    }
    if (messages_in_chunk > 0) {
      index_.start_ns = std::min(index_.start_ns, RosTimeToNs(start));
      index_.end_ns = std::max(index_.end_ns, RosTimeToNs(end));
    }
    index_.chunks.push_back(std::move(chunk));
    pos = data_pos + data_len;
  }
  return Status::Ok();
}

// Chunk headers: compression, sizes; index data records follow the data.
Status BagReader::ReadChunkHeaders() {
  std::string buffer;
  RecordHeader header;
  uint8_t op = 0;
  for (Chunk& chunk : index_.chunks) {
    TILTCAL_RETURN_IF_ERROR(
        file_.ReadRecordHeaderAt(chunk.pos, &buffer, &header, &chunk.data_pos, &chunk.data_len));
    Status status = header.GetOp(&op);
    if (status.ok() && op != static_cast<uint8_t>(Op::kChunk)) {
      status = Status::Error("chunk info points to a record with op " + std::to_string(op) +
                             " (" + OpName(op) + "), not a chunk");
    }
    if (status.ok()) status = ParseChunkHeader(header, &chunk);
    if (!status.ok()) return file_.Error(chunk.pos, "chunk: " + status.message());
    chunk.index_pos = chunk.data_pos + chunk.data_len;
  }
  return Status::Ok();
}

Status BagReader::ReadChunkIndex(size_t chunk_index, const std::vector<size_t>& connection_slots) {
  const Chunk& chunk = index_.chunks[chunk_index];
  std::string buffer;
  RecordHeader header;
  uint64_t pos = chunk.index_pos;
  uint64_t data_pos = 0;
  uint32_t data_len = 0;
  std::string data;
  for (size_t k = 0; k < chunk.connection_counts.size(); ++k) {
    TILTCAL_RETURN_IF_ERROR(file_.ReadRecordHeaderAt(pos, &buffer, &header, &data_pos, &data_len));
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
      slot = index_.ConnectionSlot(conn);
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
    if (!status.ok()) return file_.Error(pos, status.message());
    if (std::find(connection_slots.begin(), connection_slots.end(), static_cast<size_t>(slot)) !=
        connection_slots.end()) {
      data.resize(data_len);
      TILTCAL_RETURN_IF_ERROR(file_.ReadAt(data_pos, data_len, data.data()));
      std::vector<IndexEntry>& entries = index_.entries[slot];
      for (uint32_t i = 0; i < count; ++i) {
        const char* e = data.data() + i * kIndexEntrySize;
        const uint32_t offset = LoadU32Le(e + 8);
        if (offset >= chunk.size) {
          return file_.Error(pos, "index entry " + std::to_string(i) + " has offset " +
                                std::to_string(offset) + " past the chunk size " +
                                std::to_string(chunk.size));
        }
        entries.push_back(
            IndexEntry{RosTimeToNs(LoadRosTime(e)), static_cast<uint32_t>(chunk_index), offset});
      }
    }
    pos = data_pos + data_len;
  }
  return Status::Ok();
}

std::vector<std::string> BagReader::TopicsOfType(const std::string& type) const {
  std::set<std::string> topics;
  for (const Connection& c : index_.connections) {
    if (c.type == type) topics.insert(c.topic);
  }
  return {topics.begin(), topics.end()};
}

std::vector<std::string> BagReader::Topics() const {
  std::set<std::string> topics;
  for (const Connection& c : index_.connections) topics.insert(c.topic);
  return {topics.begin(), topics.end()};
}

std::string BagReader::TopicType(const std::string& topic) const {
  for (const Connection& c : index_.connections) {
    if (c.topic == topic) return c.type;
  }
  return "";
}

int64_t BagReader::MessageCount(const std::string& topic) const {
  int64_t count = 0;
  for (size_t i = 0; i < index_.connections.size(); ++i) {
    if (index_.connections[i].topic == topic) count += index_.message_counts[i];
  }
  return count;
}

int64_t BagReader::TotalMessageCount() const {
  int64_t count = 0;
  for (int64_t c : index_.message_counts) count += c;
  return count;
}

bool BagReader::TimeRange(int64_t* start_ns, int64_t* end_ns) const {
  if (index_.start_ns > index_.end_ns) return false;
  *start_ns = index_.start_ns;
  *end_ns = index_.end_ns;
  return true;
}

Status BagReader::LoadEntries(const std::vector<size_t>& slots) {
  std::vector<size_t> to_load;
  for (size_t slot : slots) {
    if (!index_.entries_loaded[slot]) to_load.push_back(slot);
  }
  if (to_load.empty()) return Status::Ok();
  for (size_t c = 0; c < index_.chunks.size(); ++c) {
    const bool wanted = std::any_of(
        index_.chunks[c].connection_counts.begin(), index_.chunks[c].connection_counts.end(),
        [&](const auto& cc) {
          return std::find(to_load.begin(), to_load.end(), static_cast<size_t>(cc.first)) !=
                 to_load.end();
        });
    if (wanted) TILTCAL_RETURN_IF_ERROR(ReadChunkIndex(c, to_load));
  }
  for (size_t slot : to_load) index_.entries_loaded[slot] = true;
  return Status::Ok();
}

std::vector<BagReader::Item> BagReader::MergedItems(const std::vector<size_t>& slots,
                                                    const ReadOptions& options) const {
  std::vector<Item> items;
  size_t total = 0;
  for (size_t slot : slots) total += index_.entries[slot].size();
  items.reserve(total);
  for (size_t slot : slots) {
    for (const IndexEntry& e : index_.entries[slot]) {
      if (e.time_ns >= options.start_ns && e.time_ns < options.end_ns) {
        items.push_back(Item{e.time_ns, e.chunk, e.offset, static_cast<uint32_t>(slot)});
      }
    }
  }
  // index_.chunks is sorted by file position, so the chunk index orders as chunk_pos.
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return std::tie(a.time_ns, a.chunk, a.offset) < std::tie(b.time_ns, b.chunk, b.offset);
  });
  return items;
}

Status BagReader::SelectSlots(const ReadOptions& options, std::vector<size_t>* slots) const {
  for (size_t i = 0; i < index_.connections.size(); ++i) {
    if (options.topics.empty() ||
        std::find(options.topics.begin(), options.topics.end(), index_.connections[i].topic) !=
            options.topics.end()) {
      slots->push_back(i);
    }
  }
  for (const std::string& topic : options.topics) {
    if (MessageCount(topic) == 0 && TopicType(topic).empty()) {
      return Status::Error(file_.path() + ": no topic '" + topic + "' in the bag");
    }
  }
  return Status::Ok();
}

std::unique_ptr<ChunkReadAhead> BagReader::StartReadAhead(const std::vector<Item>& items,
                                                          size_t depth) const {
  if (depth == 0) return nullptr;
  // The chunks in the order of their first use; later uses hit the cache
  // (or, after an eviction, load on this thread).
  std::vector<uint32_t> order;
  std::vector<bool> seen(index_.chunks.size(), false);
  for (const Item& item : items) {
    if (!seen[item.chunk]) {
      seen[item.chunk] = true;
      order.push_back(item.chunk);
    }
  }
  if (order.size() <= 1) return nullptr;
  return std::make_unique<ChunkReadAhead>(file_, index_.chunks, std::move(order), depth);
}

Status BagReader::FindMessageRecord(const Chunk& chunk, const uint8_t* buffer, size_t* offset,
                                    BufferRecord* record) const {
  // Skip connection records placed before the message (ros_comm does too).
  for (;;) {
    Status status = ParseBufferRecord(buffer, chunk.size, *offset, record);
    if (!status.ok()) return file_.Error(chunk.pos, "chunk: " + status.message());
    if (record->op != static_cast<uint8_t>(Op::kConnection)) break;
    *offset = record->end;
  }
  if (record->op != static_cast<uint8_t>(Op::kMessageData)) {
    return file_.Error(chunk.pos, "chunk: the index points to a record with op " +
                                      std::to_string(record->op) + " (" + OpName(record->op) +
                                      ") at chunk offset " + std::to_string(*offset) +
                                      ", not a message");
  }
  return Status::Ok();
}

Status BagReader::ReadMessages(const ReadOptions& options,
                               const std::function<Status(const MessageView&)>& fn) {
  std::vector<size_t> slots;
  TILTCAL_RETURN_IF_ERROR(SelectSlots(options, &slots));
  TILTCAL_RETURN_IF_ERROR(LoadEntries(slots));
  const std::vector<Item> items = MergedItems(slots, options);
  const std::unique_ptr<ChunkReadAhead> read_ahead =
      StartReadAhead(items, options.read_ahead_chunks);
  ChunkCache cache(file_, index_.chunks, &decompressor_, &stats_, options.chunk_cache_size,
                   read_ahead.get());
  MessageView view;
  for (size_t i = 0; i < items.size(); ++i) {
    const Item& item = items[i];
    const Chunk& chunk = index_.chunks[item.chunk];
    const uint8_t* buffer = nullptr;
    TILTCAL_RETURN_IF_ERROR(cache.Get(item.chunk, &buffer));
    size_t offset = item.offset;
    BufferRecord record;
    TILTCAL_RETURN_IF_ERROR(FindMessageRecord(chunk, buffer, &offset, &record));
    view.connection = &index_.connections[item.slot];
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
  for (const Chunk& chunk : index_.chunks) ++compressions[ChunkCompressionName(chunk.compression)];
  return compressions;
}

}  // namespace tiltcal::ros1
