#include "bag/ros1/bag_index.h"

namespace tiltcal::ros1 {
namespace {

// Real chunks are ~1 MB (a chunk holds at least one message, so a few
// hundred MB for a huge message at most): a larger size is a corrupt one,
// refused before it allocates.
constexpr uint32_t kMaxChunkBytes = 1u << 30;
constexpr uint32_t kLz4MaxRatio = 256;

std::string Quoted(const std::string& s) { return "'" + s + "'"; }

}  // namespace

// The uncompressed size is equal to the data bytes for an uncompressed chunk,
// at most 256 times them for lz4 (an LZ4 sequence adds at most 255 bytes of
// match per length byte); bz2, whose runs compress far more, is held to the
// 1 GiB maximum only.
Status ParseChunkHeader(const RecordHeader& header, Chunk* chunk) {
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

int BagIndex::ConnectionSlot(uint32_t id) const {
  for (size_t i = 0; i < connections.size(); ++i) {
    if (connections[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

Status BagIndex::AddConnection(const RecordHeader& header, const uint8_t* data, size_t size,
                               bool loaded) {
  Connection connection;
  Status status = header.GetU32("conn", &connection.id);
  if (status.ok()) status = header.GetString("topic", &connection.topic);
  RecordHeader inner;
  if (status.ok()) status = inner.Parse(data, size);
  if (!status.ok()) return Status::Error("connection record: " + status.message());
  if (ConnectionSlot(connection.id) >= 0) return Status::Ok();  // seen in a chunk already
  // The inner block may lack `topic` (recorded live); the outer one is authoritative.
  if (inner.Has("type")) (void)inner.GetString("type", &connection.type);
  if (inner.Has("md5sum")) (void)inner.GetString("md5sum", &connection.md5sum);
  if (inner.Has("message_definition")) {
    (void)inner.GetString("message_definition", &connection.message_definition);
  }
  if (inner.Has("callerid")) (void)inner.GetString("callerid", &connection.callerid);
  connections.push_back(std::move(connection));
  message_counts.push_back(0);
  entries.emplace_back();
  entries_loaded.push_back(loaded);
  return Status::Ok();
}

}  // namespace tiltcal::ros1
