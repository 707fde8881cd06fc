#ifndef TILTCAL_BAG_MCAP_FORMAT_H_
#define TILTCAL_BAG_MCAP_FORMAT_H_

// Primitives of the MCAP format (mcap.dev/spec, version 0), shared by the
// reader's parts. Nothing here does file I/O.
//
// File:    magic (8 bytes) · Header record · data section · DataEnd record
//          · summary section (optional) · summary offsets (optional)
//          · Footer record · magic
// Record:  opcode:u8 · length:u64 · content (length bytes)
// Content: integers little endian; string = u32 length + bytes;
//          bytes = u32 or u64 length + bytes; map = u32 byte length + entries.
// Records used here (opcode: content):
//   0x01 Header      profile string, library string
//   0x02 Footer      summary_start u64, summary_offset_start u64, summary_crc u32
//   0x03 Schema      id u16, name string, encoding string, data (u32 length)
//   0x04 Channel     id u16, schema_id u16, topic string, message_encoding string,
//                    metadata map<string, string>
//   0x05 Message     channel_id u16, sequence u32, log_time u64, publish_time u64,
//                    data = the rest of the record
//   0x06 Chunk       message_start_time u64, message_end_time u64,
//                    uncompressed_size u64, uncompressed_crc u32 (0 = none),
//                    compression string ("", "lz4", "zstd"), records (u64 length)
//   0x07 MessageIndex  channel_id u16, entries (u32 byte length) of
//                    (log_time u64, offset u64 into the uncompressed chunk records)
//   0x08 ChunkIndex  message_start_time u64, message_end_time u64,
//                    chunk_start_offset u64, chunk_length u64,
//                    message_index_offsets map<u16, u64>, message_index_length u64,
//                    compression string, compressed_size u64, uncompressed_size u64
//   0x0F DataEnd     data_section_crc u32
// Every other opcode is skipped. Times are ns since the epoch.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"

namespace tiltcal::mcap {

inline constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
inline constexpr size_t kRecordPrefixBytes = 9;  // opcode + u64 length
inline constexpr size_t kFooterBytes = kRecordPrefixBytes + 20;

enum Opcode : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kDataEnd = 0x0F,
};

// "Header", "Chunk", ...; "opcode N" for any other.
std::string OpcodeName(uint8_t opcode);
// Opcodes a record of the data section may have when looking for where the
// records resume after a damaged one: the known records and the private
// ones (0x80 and up).
bool CanStartRecord(uint8_t opcode);
// No record of a sane recording is this large; readers refuse it before
// allocating.
inline constexpr uint64_t kMaxRecordBytes = uint64_t{4} << 30;

// The little-endian u64 at `p` (any alignment).
inline uint64_t LoadU64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

// CRC-32 (ISO-HDLC, as zlib's crc32) of `size` bytes, continuing from `crc`.
uint32_t Crc32(const uint8_t* data, size_t size, uint32_t crc = 0);

// A bounds-checked cursor over the content of one record. Errors name the
// field; the caller adds file and offset.
class FieldReader {
 public:
  FieldReader(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  Status U16(const char* what, uint16_t* v);
  Status U32(const char* what, uint32_t* v);
  Status U64(const char* what, uint64_t* v);
  Status String(const char* what, std::string* s);
  // `n` bytes (a view, no copy).
  Status Bytes(const char* what, uint64_t n, const uint8_t** bytes);
  // A u32 (or u64) length, then that many bytes.
  Status Bytes32(const char* what, const uint8_t** bytes, uint64_t* n);
  Status Bytes64(const char* what, const uint8_t** bytes, uint64_t* n);

  size_t position() const { return pos_; }
  size_t remaining() const { return size_ - pos_; }
  const uint8_t* here() const { return data_ + pos_; }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

// The fields of records the reader uses.
struct SchemaRecord {
  uint16_t id = 0;
  std::string name;
  std::string encoding;
};
struct ChannelRecord {
  uint16_t id = 0;
  uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;
};
struct ChunkRecord {
  uint64_t start_time = 0;
  uint64_t end_time = 0;
  uint64_t uncompressed_size = 0;
  uint32_t uncompressed_crc = 0;
  std::string compression;
  const uint8_t* records = nullptr;  // view into the record content
  uint64_t records_size = 0;
};
struct ChunkIndexRecord {
  uint64_t start_time = 0;
  uint64_t end_time = 0;
  uint64_t chunk_start_offset = 0;
  uint64_t chunk_length = 0;
  std::vector<std::pair<uint16_t, uint64_t>> message_index_offsets;  // channel, file offset
  std::string compression;
  uint64_t compressed_size = 0;
  uint64_t uncompressed_size = 0;
};
// The fixed fields of a Message record; the data follows them.
inline constexpr size_t kMessageFixedBytes = 2 + 4 + 8 + 8;
struct MessageRecord {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  const uint8_t* data = nullptr;
  size_t size = 0;
};

Status ParseSchema(const uint8_t* content, size_t size, SchemaRecord* r);
Status ParseChannel(const uint8_t* content, size_t size, ChannelRecord* r);
Status ParseChunk(const uint8_t* content, size_t size, ChunkRecord* r);
Status ParseChunkIndex(const uint8_t* content, size_t size, ChunkIndexRecord* r);
Status ParseMessage(const uint8_t* content, size_t size, MessageRecord* r);
// Calls fn(log_time, offset) for every entry of a MessageIndex record;
// *channel_id gets its channel.
Status ParseMessageIndex(const uint8_t* content, size_t size, uint16_t* channel_id,
                         const std::function<void(uint64_t, uint64_t)>& fn);

}  // namespace tiltcal::mcap

#endif  // TILTCAL_BAG_MCAP_FORMAT_H_
