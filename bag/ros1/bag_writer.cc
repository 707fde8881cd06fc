#include "bag/ros1/bag_writer.h"

#include <algorithm>
#include <cstdio>
#include <thread>

#include "bag/ros1/format.h"

namespace tiltcal::ros1 {

namespace {

// The header value of a time given in ns since the epoch.
Status NsTimeValue(int64_t ns, std::string* value) {
  RosTime t;
  if (!NsToRosTime(ns, &t)) {
    return Status::Error("time " + std::to_string(ns) + " ns is not a valid ROS time");
  }
  *value = TimeValue(t);
  return Status::Ok();
}

std::string TimeValueOrZero(int64_t ns) {
  std::string value;
  if (!NsTimeValue(ns, &value).ok()) value = TimeValue(RosTime{});
  return value;
}

}  // namespace

Status BagWriter::Open(const std::string& path, ChunkCompression compression,
                       uint32_t chunk_threshold_bytes, unsigned compression_threads) {
  path_ = path;
  compression_threads_ = std::max(1u, compression_threads);
  compression_ = compression;
  chunk_threshold_ = chunk_threshold_bytes;
  TILTCAL_RETURN_IF_ERROR(file_.Open(path));
  open_ = true;
  TILTCAL_RETURN_IF_ERROR(WriteBytes(kVersionLine));
  // Placeholder header (index_pos 0 = unindexed), rewritten by Close().
  return WriteBytes(BagHeaderRecord(0));
}

uint32_t BagWriter::AddConnection(const std::string& topic, const std::string& type,
                                  const std::string& md5sum, const std::string& definition) {
  connections_.push_back({topic, type, md5sum, definition, false});
  return static_cast<uint32_t>(connections_.size() - 1);
}

Status BagWriter::WriteBytes(std::string_view bytes) {
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file_.file()) != bytes.size()) {
    return Status::Error(path_ + ": write failed at byte " + std::to_string(position_));
  }
  position_ += bytes.size();
  return Status::Ok();
}

std::string BagWriter::BagHeaderRecord(uint64_t index_position) const {
  HeaderFields fields;
  fields["op"] = OpValue(Op::kBagHeader);
  fields["index_pos"] = U64Value(index_position);
  fields["conn_count"] = U32Value(static_cast<uint32_t>(connections_.size()));
  fields["chunk_count"] = U32Value(static_cast<uint32_t>(chunk_infos_.size()));
  const std::string header = BuildHeader(fields);
  // header_len + data_len = 4096: the data is space padding.
  const size_t padding = kBagHeaderPaddedSize - header.size();
  std::string record;
  AppendRecord(&record, fields, std::string(padding, ' '));
  return record;
}

std::string BagWriter::ConnectionRecord(uint32_t id) const {
  const Connection& c = connections_[id];
  HeaderFields fields;
  fields["op"] = OpValue(Op::kConnection);
  fields["conn"] = U32Value(id);
  fields["topic"] = c.topic;
  // Data: the connection header as a publisher sends it.
  HeaderFields data;
  data["topic"] = c.topic;
  data["type"] = c.type;
  data["md5sum"] = c.md5sum;
  data["message_definition"] = c.definition;
  std::string record;
  AppendRecord(&record, fields, BuildHeader(data));
  return record;
}

Status BagWriter::Write(uint32_t connection, int64_t time_ns, std::string_view message) {
  if (!open_) return Status::Error(path_ + ": bag is not open");
  if (connection >= connections_.size()) {
    return Status::Error(path_ + ": unknown connection " + std::to_string(connection));
  }
  std::string time_value;
  TILTCAL_RETURN_IF_ERROR(NsTimeValue(time_ns, &time_value).WithContext(path_));
  Connection& c = connections_[connection];
  if (!c.written) {
    chunk_ += ConnectionRecord(connection);
    c.written = true;
  }
  if (chunk_index_.empty()) {
    chunk_start_ns_ = chunk_end_ns_ = time_ns;
  }
  chunk_start_ns_ = std::min(chunk_start_ns_, time_ns);
  chunk_end_ns_ = std::max(chunk_end_ns_, time_ns);
  chunk_index_[connection].push_back({time_ns, static_cast<uint32_t>(chunk_.size())});
  HeaderFields fields;
  fields["op"] = OpValue(Op::kMessageData);
  fields["conn"] = U32Value(connection);
  fields["time"] = time_value;
  AppendRecord(&chunk_, fields, message);
  if (chunk_.size() >= chunk_threshold_) return FlushChunk();
  return Status::Ok();
}

Status BagWriter::FlushChunk() {
  if (chunk_index_.empty()) return Status::Ok();
  pending_.push_back({std::move(chunk_), std::move(chunk_index_), chunk_start_ns_, chunk_end_ns_});
  chunk_.clear();
  chunk_index_.clear();
  if (pending_.size() >= compression_threads_) return WritePendingChunks();
  return Status::Ok();
}

Status BagWriter::WritePendingChunks() {
  // Compress the pending chunks in parallel, then write them in order.
  const size_t n = pending_.size();
  std::vector<std::string> compressed(n);
  std::vector<Status> status(n);
  if (compression_ != ChunkCompression::kNone) {
    auto work = [&](size_t first) {
      for (size_t i = first; i < n; i += compression_threads_) {
        status[i] = CompressChunk(compression_, pending_[i].data, &compressed[i]);
      }
    };
    std::vector<std::thread> pool;
    for (size_t t = 1; t < std::min<size_t>(compression_threads_, n); ++t) pool.emplace_back(work, t);
    work(0);
    for (auto& th : pool) th.join();
  }
  for (size_t i = 0; i < n; ++i) {
    TILTCAL_RETURN_IF_ERROR(status[i].WithContext(path_));
    const PendingChunk& chunk = pending_[i];
    const std::string_view data =
        compression_ == ChunkCompression::kNone ? std::string_view(chunk.data) : compressed[i];
    ChunkInfo info;
    info.position = position_;
    info.start_ns = chunk.start_ns;
    info.end_ns = chunk.end_ns;
    HeaderFields fields;
    fields["op"] = OpValue(Op::kChunk);
    fields["compression"] = ChunkCompressionName(compression_);
    fields["size"] = U32Value(static_cast<uint32_t>(chunk.data.size()));
    std::string record;
    AppendRecord(&record, fields, data);
    TILTCAL_RETURN_IF_ERROR(WriteBytes(record));
    // Index data: one record per connection of the chunk, ascending ids.
    for (const auto& [conn, entries] : chunk.index) {
      HeaderFields index;
      index["op"] = OpValue(Op::kIndexData);
      index["ver"] = U32Value(kIndexDataVersion);
      index["conn"] = U32Value(conn);
      index["count"] = U32Value(static_cast<uint32_t>(entries.size()));
      std::string body;
      body.reserve(entries.size() * kIndexEntrySize);
      for (const IndexEntry& e : entries) {
        body += TimeValueOrZero(e.time_ns);
        AppendU32Le(&body, e.offset);
      }
      record.clear();
      AppendRecord(&record, index, body);
      TILTCAL_RETURN_IF_ERROR(WriteBytes(record));
      info.counts[conn] = static_cast<uint32_t>(entries.size());
    }
    chunk_infos_.push_back(std::move(info));
  }
  pending_.clear();
  return Status::Ok();
}

Status BagWriter::Close() {
  if (!open_) return Status::Error(path_ + ": bag is not open");
  TILTCAL_RETURN_IF_ERROR(FlushChunk());
  TILTCAL_RETURN_IF_ERROR(WritePendingChunks());
  const uint64_t index_position = position_;
  for (uint32_t id = 0; id < connections_.size(); ++id) {
    TILTCAL_RETURN_IF_ERROR(WriteBytes(ConnectionRecord(id)));
  }
  for (const ChunkInfo& info : chunk_infos_) {
    HeaderFields fields;
    fields["op"] = OpValue(Op::kChunkInfo);
    fields["ver"] = U32Value(kChunkInfoVersion);
    fields["chunk_pos"] = U64Value(info.position);
    fields["start_time"] = TimeValueOrZero(info.start_ns);
    fields["end_time"] = TimeValueOrZero(info.end_ns);
    fields["count"] = U32Value(static_cast<uint32_t>(info.counts.size()));
    std::string body;
    for (const auto& [conn, count] : info.counts) {
      AppendU32Le(&body, conn);
      AppendU32Le(&body, count);
    }
    std::string record;
    AppendRecord(&record, fields, body);
    TILTCAL_RETURN_IF_ERROR(WriteBytes(record));
  }
  // Final bag header over the placeholder (same size).
  if (std::fseek(file_.file(), static_cast<long>(kVersionLine.size()), SEEK_SET) != 0) {
    return Status::Error(path_ + ": seek failed");
  }
  const std::string header = BagHeaderRecord(index_position);
  if (std::fwrite(header.data(), 1, header.size(), file_.file()) != header.size()) {
    return Status::Error(path_ + ": write of the bag header failed");
  }
  open_ = false;
  return file_.Commit();
}

}  // namespace tiltcal::ros1
