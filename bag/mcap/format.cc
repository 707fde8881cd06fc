#include "bag/mcap/format.h"

#include <array>
#include <cstring>

namespace tiltcal::mcap {

namespace {

// Slicing-by-8 tables: t[0] is the bytewise table of the reflected
// polynomial 0xEDB88320; t[k][i] = CRC of byte i followed by k zero bytes.
using CrcTables = std::array<std::array<uint32_t, 256>, 8>;
CrcTables MakeCrcTables() {
  CrcTables t{};
  for (uint32_t i = 0; i < 256; ++i) {
    uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (uint32_t i = 0; i < 256; ++i) {
    for (size_t k = 1; k < 8; ++k) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFF];
  }
  return t;
}

template <typename T>
T LoadLe(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));  // the host is little endian
  return v;
}

}  // namespace

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

bool CanStartRecord(uint8_t opcode) {
  return (opcode >= kSchema && opcode <= kDataEnd) || opcode >= 0x80;
}

uint32_t Crc32(const uint8_t* data, size_t size, uint32_t crc) {
  static const CrcTables t = MakeCrcTables();
  crc = ~crc;
  size_t i = 0;
  for (; i + 8 <= size; i += 8) {  // 8 bytes per step (little-endian host)
    const uint32_t lo = LoadLe<uint32_t>(data + i) ^ crc;
    const uint32_t hi = LoadLe<uint32_t>(data + i + 4);
    crc = t[7][lo & 0xFF] ^ t[6][(lo >> 8) & 0xFF] ^ t[5][(lo >> 16) & 0xFF] ^ t[4][lo >> 24] ^
          t[3][hi & 0xFF] ^ t[2][(hi >> 8) & 0xFF] ^ t[1][(hi >> 16) & 0xFF] ^ t[0][hi >> 24];
  }
  for (; i < size; ++i) crc = t[0][(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

Status FieldReader::Bytes(const char* what, uint64_t n, const uint8_t** bytes) {
  if (n > size_ - pos_) {
    return Status::Error(std::string(what) + " needs " + std::to_string(n) + " bytes at byte " +
                         std::to_string(pos_) + " of a record of " + std::to_string(size_));
  }
  *bytes = data_ + pos_;
  pos_ += n;
  return Status::Ok();
}

Status FieldReader::U16(const char* what, uint16_t* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Bytes(what, 2, &p));
  *v = LoadLe<uint16_t>(p);
  return Status::Ok();
}

Status FieldReader::U32(const char* what, uint32_t* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Bytes(what, 4, &p));
  *v = LoadLe<uint32_t>(p);
  return Status::Ok();
}

Status FieldReader::U64(const char* what, uint64_t* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Bytes(what, 8, &p));
  *v = LoadLe<uint64_t>(p);
  return Status::Ok();
}

Status FieldReader::String(const char* what, std::string* s) {
  const uint8_t* p = nullptr;
  uint64_t n = 0;
  TILTCAL_RETURN_IF_ERROR(Bytes32(what, &p, &n));
  s->assign(reinterpret_cast<const char*>(p), n);
  return Status::Ok();
}

Status FieldReader::Bytes32(const char* what, const uint8_t** bytes, uint64_t* n) {
  uint32_t n32 = 0;
  TILTCAL_RETURN_IF_ERROR(U32(what, &n32));
  *n = n32;
  return Bytes(what, n32, bytes);
}

Status FieldReader::Bytes64(const char* what, const uint8_t** bytes, uint64_t* n) {
  TILTCAL_RETURN_IF_ERROR(U64(what, n));
  return Bytes(what, *n, bytes);
}

Status ParseSchema(const uint8_t* content, size_t size, SchemaRecord* r) {
  FieldReader f(content, size);
  TILTCAL_RETURN_IF_ERROR(f.U16("schema id", &r->id));
  TILTCAL_RETURN_IF_ERROR(f.String("schema name", &r->name));
  return f.String("schema encoding", &r->encoding);
}

Status ParseChannel(const uint8_t* content, size_t size, ChannelRecord* r) {
  FieldReader f(content, size);
  TILTCAL_RETURN_IF_ERROR(f.U16("channel id", &r->id));
  TILTCAL_RETURN_IF_ERROR(f.U16("channel schema_id", &r->schema_id));
  TILTCAL_RETURN_IF_ERROR(f.String("channel topic", &r->topic));
  return f.String("channel message_encoding", &r->message_encoding);
}

Status ParseChunk(const uint8_t* content, size_t size, ChunkRecord* r) {
  FieldReader f(content, size);
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk message_start_time", &r->start_time));
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk message_end_time", &r->end_time));
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk uncompressed_size", &r->uncompressed_size));
  TILTCAL_RETURN_IF_ERROR(f.U32("chunk uncompressed_crc", &r->uncompressed_crc));
  TILTCAL_RETURN_IF_ERROR(f.String("chunk compression", &r->compression));
  return f.Bytes64("chunk records", &r->records, &r->records_size);
}

Status ParseChunkIndex(const uint8_t* content, size_t size, ChunkIndexRecord* r) {
  FieldReader f(content, size);
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk index message_start_time", &r->start_time));
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk index message_end_time", &r->end_time));
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk index chunk_start_offset", &r->chunk_start_offset));
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk index chunk_length", &r->chunk_length));
  const uint8_t* map = nullptr;
  uint64_t map_size = 0;
  TILTCAL_RETURN_IF_ERROR(f.Bytes32("chunk index message_index_offsets", &map, &map_size));
  FieldReader m(map, map_size);
  r->message_index_offsets.clear();
  while (m.remaining() > 0) {
    uint16_t channel = 0;
    uint64_t offset = 0;
    TILTCAL_RETURN_IF_ERROR(m.U16("message_index_offsets channel", &channel));
    TILTCAL_RETURN_IF_ERROR(m.U64("message_index_offsets offset", &offset));
    r->message_index_offsets.emplace_back(channel, offset);
  }
  uint64_t message_index_length = 0;
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk index message_index_length", &message_index_length));
  TILTCAL_RETURN_IF_ERROR(f.String("chunk index compression", &r->compression));
  TILTCAL_RETURN_IF_ERROR(f.U64("chunk index compressed_size", &r->compressed_size));
  return f.U64("chunk index uncompressed_size", &r->uncompressed_size);
}

Status ParseMessage(const uint8_t* content, size_t size, MessageRecord* r) {
  FieldReader f(content, size);
  TILTCAL_RETURN_IF_ERROR(f.U16("message channel_id", &r->channel_id));
  TILTCAL_RETURN_IF_ERROR(f.U32("message sequence", &r->sequence));
  TILTCAL_RETURN_IF_ERROR(f.U64("message log_time", &r->log_time));
  TILTCAL_RETURN_IF_ERROR(f.U64("message publish_time", &r->publish_time));
  r->data = f.here();
  r->size = f.remaining();
  return Status::Ok();
}

Status ParseMessageIndex(const uint8_t* content, size_t size, uint16_t* channel_id,
                         const std::function<void(uint64_t, uint64_t)>& fn) {
  FieldReader f(content, size);
  TILTCAL_RETURN_IF_ERROR(f.U16("message index channel_id", channel_id));
  const uint8_t* entries = nullptr;
  uint64_t entries_size = 0;
  TILTCAL_RETURN_IF_ERROR(f.Bytes32("message index records", &entries, &entries_size));
  if (entries_size % 16 != 0) {
    return Status::Error("message index records of " + std::to_string(entries_size) +
                         " bytes, not a multiple of 16");
  }
  for (uint64_t i = 0; i < entries_size; i += 16) {
    fn(LoadLe<uint64_t>(entries + i), LoadLe<uint64_t>(entries + i + 8));
  }
  return Status::Ok();
}

}  // namespace tiltcal::mcap
