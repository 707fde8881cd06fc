#include "stages/simulate/ros1_bag_writer.h"

#include <bzlib.h>
#include <lz4frame.h>

#include <algorithm>
#include <cstdio>
#include <thread>

#include "stages/decode/ros1_format.h"

namespace tiltcal::simulate {

namespace {

using ros1::HeaderFields;
using ros1::Op;

Status TimeValue(int64_t ns, std::string* value) {
  ros1::RosTime t;
  if (!ros1::NsToRosTime(ns, &t)) {
    return Status::Error("time " + std::to_string(ns) + " ns is not a valid ROS time");
  }
  *value = ros1::TimeValue(t);
  return Status::Ok();
}

std::string TimeValueOrZero(int64_t ns) {
  std::string value;
  if (!TimeValue(ns, &value).ok()) value = ros1::TimeValue(ros1::RosTime{});
  return value;
}

// roslz4's frame: block independence, 1 MiB blocks (id 6), content checksum,
// no content size, no block checksums (FLG 0x64, BD 0x60).
Status CompressLz4(const std::string& in, std::string* out) {
  LZ4F_preferences_t prefs = LZ4F_INIT_PREFERENCES;
  prefs.frameInfo.blockSizeID = LZ4F_max1MB;
  prefs.frameInfo.blockMode = LZ4F_blockIndependent;
  prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
  prefs.frameInfo.contentSize = 0;
  prefs.frameInfo.blockChecksumFlag = LZ4F_noBlockChecksum;
  prefs.compressionLevel = 0;
  out->resize(LZ4F_compressFrameBound(in.size(), &prefs));
  const size_t n = LZ4F_compressFrame(out->data(), out->size(), in.data(), in.size(), &prefs);
  if (LZ4F_isError(n)) {
    return Status::Error(std::string("lz4 compression failed: ") + LZ4F_getErrorName(n));
  }
  out->resize(n);
  return Status::Ok();
}

// One bzip2 stream, block size 900k ("BZh9"), as ros_comm's bz2 stream.
Status CompressBz2(const std::string& in, std::string* out) {
  unsigned int size = static_cast<unsigned int>(in.size() + in.size() / 100 + 600);
  out->resize(size);
  const int rc = BZ2_bzBuffToBuffCompress(out->data(), &size, const_cast<char*>(in.data()),
                                          static_cast<unsigned int>(in.size()), 9, 0, 30);
  if (rc != BZ_OK) return Status::Error("bz2 compression failed, code " + std::to_string(rc));
  out->resize(size);
  return Status::Ok();
}

}  // namespace

const char* Ros1BagWriter::CompressionName(Compression compression) {
  switch (compression) {
    case Compression::kBz2: return "bz2";
    case Compression::kLz4: return "lz4";
    default: return "none";
  }
}

Status Ros1BagWriter::Open(const std::string& path, Compression compression,
                           uint32_t chunk_threshold_bytes, unsigned compression_threads) {
  path_ = path;
  compression_threads_ = std::max(1u, compression_threads);
  compression_ = compression;
  chunk_threshold_ = chunk_threshold_bytes;
  TILTCAL_RETURN_IF_ERROR(file_.Open(path));
  open_ = true;
  TILTCAL_RETURN_IF_ERROR(WriteBytes(ros1::kVersionLine));
  // Placeholder header (index_pos 0 = unindexed), rewritten by Close().
  return WriteBytes(BagHeaderRecord(0));
}

uint32_t Ros1BagWriter::AddConnection(const std::string& topic, const std::string& type,
                                      const std::string& md5sum, const std::string& definition) {
  connections_.push_back({topic, type, md5sum, definition, false});
  return static_cast<uint32_t>(connections_.size() - 1);
}

Status Ros1BagWriter::WriteBytes(std::string_view bytes) {
  if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file_.file()) != bytes.size()) {
    return Status::Error(path_ + ": write failed at byte " + std::to_string(position_));
  }
  position_ += bytes.size();
  return Status::Ok();
}

std::string Ros1BagWriter::BagHeaderRecord(uint64_t index_position) const {
  HeaderFields fields;
  fields["op"] = ros1::OpValue(Op::kBagHeader);
  fields["index_pos"] = ros1::U64Value(index_position);
  fields["conn_count"] = ros1::U32Value(static_cast<uint32_t>(connections_.size()));
  fields["chunk_count"] = ros1::U32Value(static_cast<uint32_t>(chunk_infos_.size()));
  const std::string header = ros1::BuildHeader(fields);
  // header_len + data_len = 4096: the data is space padding.
  const size_t padding = ros1::kBagHeaderPaddedSize - header.size();
  std::string record;
  ros1::AppendRecord(&record, fields, std::string(padding, ' '));
  return record;
}

std::string Ros1BagWriter::ConnectionRecord(uint32_t id) const {
  const Connection& c = connections_[id];
  HeaderFields fields;
  fields["op"] = ros1::OpValue(Op::kConnection);
  fields["conn"] = ros1::U32Value(id);
  fields["topic"] = c.topic;
  // Data: the connection header as a publisher sends it.
  HeaderFields data;
  data["topic"] = c.topic;
  data["type"] = c.type;
  data["md5sum"] = c.md5sum;
  data["message_definition"] = c.definition;
  std::string record;
  ros1::AppendRecord(&record, fields, ros1::BuildHeader(data));
  return record;
}

Status Ros1BagWriter::Write(uint32_t connection, int64_t time_ns, std::string_view message) {
  if (!open_) return Status::Error(path_ + ": bag is not open");
  if (connection >= connections_.size()) {
    return Status::Error(path_ + ": unknown connection " + std::to_string(connection));
  }
  std::string time_value;
  TILTCAL_RETURN_IF_ERROR(TimeValue(time_ns, &time_value).WithContext(path_));
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
  fields["op"] = ros1::OpValue(Op::kMessageData);
  fields["conn"] = ros1::U32Value(connection);
  fields["time"] = time_value;
  ros1::AppendRecord(&chunk_, fields, message);
  if (chunk_.size() >= chunk_threshold_) return FlushChunk();
  return Status::Ok();
}

Status Ros1BagWriter::FlushChunk() {
  if (chunk_index_.empty()) return Status::Ok();
  pending_.push_back({std::move(chunk_), std::move(chunk_index_), chunk_start_ns_, chunk_end_ns_});
  chunk_.clear();
  chunk_index_.clear();
  if (pending_.size() >= compression_threads_) return WritePendingChunks();
  return Status::Ok();
}

Status Ros1BagWriter::WritePendingChunks() {
  // Compress the pending chunks in parallel, then write them in order.
  const size_t n = pending_.size();
  std::vector<std::string> compressed(n);
  std::vector<Status> status(n);
  if (compression_ != Compression::kNone) {
    auto work = [&](size_t first) {
      for (size_t i = first; i < n; i += compression_threads_) {
        status[i] = compression_ == Compression::kLz4 ? CompressLz4(pending_[i].data, &compressed[i])
                                                      : CompressBz2(pending_[i].data, &compressed[i]);
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
        compression_ == Compression::kNone ? std::string_view(chunk.data) : compressed[i];
    ChunkInfo info;
    info.position = position_;
    info.start_ns = chunk.start_ns;
    info.end_ns = chunk.end_ns;
    HeaderFields fields;
    fields["op"] = ros1::OpValue(Op::kChunk);
    fields["compression"] = CompressionName(compression_);
    fields["size"] = ros1::U32Value(static_cast<uint32_t>(chunk.data.size()));
    std::string record;
    ros1::AppendRecord(&record, fields, data);
    TILTCAL_RETURN_IF_ERROR(WriteBytes(record));
    // Index data: one record per connection of the chunk, ascending ids.
    for (const auto& [conn, entries] : chunk.index) {
      HeaderFields index;
      index["op"] = ros1::OpValue(Op::kIndexData);
      index["ver"] = ros1::U32Value(ros1::kIndexDataVersion);
      index["conn"] = ros1::U32Value(conn);
      index["count"] = ros1::U32Value(static_cast<uint32_t>(entries.size()));
      std::string body;
      body.reserve(entries.size() * ros1::kIndexEntrySize);
      for (const IndexEntry& e : entries) {
        body += TimeValueOrZero(e.time_ns);
        ros1::AppendU32Le(&body, e.offset);
      }
      record.clear();
      ros1::AppendRecord(&record, index, body);
      TILTCAL_RETURN_IF_ERROR(WriteBytes(record));
      info.counts[conn] = static_cast<uint32_t>(entries.size());
    }
    chunk_infos_.push_back(std::move(info));
  }
  pending_.clear();
  return Status::Ok();
}

Status Ros1BagWriter::Close() {
  if (!open_) return Status::Error(path_ + ": bag is not open");
  TILTCAL_RETURN_IF_ERROR(FlushChunk());
  TILTCAL_RETURN_IF_ERROR(WritePendingChunks());
  const uint64_t index_position = position_;
  for (uint32_t id = 0; id < connections_.size(); ++id) {
    TILTCAL_RETURN_IF_ERROR(WriteBytes(ConnectionRecord(id)));
  }
  for (const ChunkInfo& info : chunk_infos_) {
    HeaderFields fields;
    fields["op"] = ros1::OpValue(Op::kChunkInfo);
    fields["ver"] = ros1::U32Value(ros1::kChunkInfoVersion);
    fields["chunk_pos"] = ros1::U64Value(info.position);
    fields["start_time"] = TimeValueOrZero(info.start_ns);
    fields["end_time"] = TimeValueOrZero(info.end_ns);
    fields["count"] = ros1::U32Value(static_cast<uint32_t>(info.counts.size()));
    std::string body;
    for (const auto& [conn, count] : info.counts) {
      ros1::AppendU32Le(&body, conn);
      ros1::AppendU32Le(&body, count);
    }
    std::string record;
    ros1::AppendRecord(&record, fields, body);
    TILTCAL_RETURN_IF_ERROR(WriteBytes(record));
  }
  // Final bag header over the placeholder (same size).
  if (std::fseek(file_.file(), static_cast<long>(ros1::kVersionLine.size()), SEEK_SET) != 0) {
    return Status::Error(path_ + ": seek failed");
  }
  const std::string header = BagHeaderRecord(index_position);
  if (std::fwrite(header.data(), 1, header.size(), file_.file()) != header.size()) {
    return Status::Error(path_ + ": write of the bag header failed");
  }
  open_ = false;
  return file_.Commit();
}

}  // namespace tiltcal::simulate
