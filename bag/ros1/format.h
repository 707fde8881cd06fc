#ifndef TILTCAL_BAG_ROS1_FORMAT_H_
#define TILTCAL_BAG_ROS1_FORMAT_H_

// Primitives of the ROS1 bag format 2.0 (wiki.ros.org/Bags/Format/2.0),
// shared by the bag reader and the bag writer. Nothing here does file I/O.
//
// File layout:
//   "#ROSBAG V2.0\n" · bag header record (padded so header_len + data_len = 4096)
//   · { chunk record · index data record per connection in the chunk }*
//   · connection record * conn_count · chunk info record * chunk_count
// Record:  header_len:u32le · header · data_len:u32le · data
// Header:  { field_len:u32le · name '=' value }*  (field_len = |name| + 1 + |value|;
//          split at the FIRST '='; values are binary, integers little-endian;
//          fields in any order, unknown fields ignored).
// Time:    8 bytes, u32 sec then u32 nsec, little-endian.

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "bag/sensor_messages.h"
#include "common/status.h"

namespace tiltcal::ros1 {

// The version line every v2.0 bag starts with (13 bytes, no NUL).
inline constexpr std::string_view kVersionLine = "#ROSBAG V2.0\n";
// header_len + data_len of the bag header record (FILE_HEADER_LENGTH); the
// data is ASCII spaces padding it to this size.
inline constexpr uint32_t kBagHeaderPaddedSize = 4096;
// Version of index data (op 0x04) and chunk info (op 0x06) records.
inline constexpr uint32_t kIndexDataVersion = 1;
inline constexpr uint32_t kChunkInfoVersion = 1;
// Bytes per entry of an index data record: time (8) + offset (4).
inline constexpr size_t kIndexEntrySize = 12;

// Record op codes (header field "op", 1 byte).
enum class Op : uint8_t {
  kMessageDefinition = 0x01,  // v1.2 only
  kMessageData = 0x02,        // conn u32, time: serialized message
  kBagHeader = 0x03,          // index_pos u64, conn_count u32, chunk_count u32
  kIndexData = 0x04,          // ver u32, conn u32, count u32: count x (time, offset u32)
  kChunk = 0x05,              // compression string, size u32 (uncompressed bytes)
  kChunkInfo = 0x06,          // ver, chunk_pos u64, start_time, end_time, count u32
  kConnection = 0x07,         // conn u32, topic: data = header block (topic, type, md5sum, ...)
};

// Human-readable name of an op code, e.g. "chunk"; "unknown" otherwise.
const char* OpName(uint8_t op);

// ---- Little-endian helpers (unaligned-safe: always memcpy). ----
// The host is little-endian (checked in format.cc).
template <typename T>
inline T LoadLe(const void* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  return value;
}
inline uint32_t LoadU32Le(const void* p) { return LoadLe<uint32_t>(p); }
inline uint64_t LoadU64Le(const void* p) { return LoadLe<uint64_t>(p); }

template <typename T>
inline void AppendLe(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out->append(bytes, sizeof(T));
}
inline void AppendU32Le(std::string* out, uint32_t value) { AppendLe(out, value); }
inline void AppendU64Le(std::string* out, uint64_t value) { AppendLe(out, value); }

// ---- ROS time (u32 sec, u32 nsec) <-> int64 ns since epoch. ----
// RosTime and RosTimeToNs are shared with ROS 2 (bag/sensor_messages.h).
using bag::RosTime;
using bag::RosTimeToNs;
// False when `ns` is negative or beyond u32 seconds.
bool NsToRosTime(int64_t ns, RosTime* t);
// Decodes / encodes the 8 bytes of a time value.
inline RosTime LoadRosTime(const void* p) {
  const auto* b = static_cast<const unsigned char*>(p);
  return RosTime{LoadU32Le(b), LoadU32Le(b + 4)};
}
inline void AppendRosTime(std::string* out, RosTime t) {
  AppendU32Le(out, t.sec);
  AppendU32Le(out, t.nsec);
}

// ---- Record header parsing. ----
// A parsed header: views into the caller's buffer, which must outlive it.
class RecordHeader {
 public:
  // Parses `size` bytes of name=value fields. Errors (a field length past the
  // end, a field without '=') name the field's byte offset in the header.
  Status Parse(const void* data, size_t size);

  // The value of field `name`, or nullptr when absent. With duplicate names
  // the last one wins (as in ros_comm, which fills a std::map).
  const std::string_view* Find(std::string_view name) const;
  bool Has(std::string_view name) const { return Find(name) != nullptr; }

  // Typed getters: a missing field or a value of the wrong size is an error
  // naming the field, e.g. "header field 'conn' has 3 bytes, expected 4".
  Status GetOp(uint8_t* op) const;
  Status GetU32(std::string_view name, uint32_t* value) const;
  Status GetU64(std::string_view name, uint64_t* value) const;
  Status GetTime(std::string_view name, RosTime* value) const;
  Status GetString(std::string_view name, std::string* value) const;

  const std::vector<std::pair<std::string_view, std::string_view>>& fields() const {
    return fields_;
  }

 private:
  std::vector<std::pair<std::string_view, std::string_view>> fields_;
};

// ---- Records inside a decompressed chunk. ----
// One record of a chunk buffer: header fields and data are views into it.
struct BufferRecord {
  RecordHeader header;
  uint8_t op = 0;
  const uint8_t* data = nullptr;
  uint32_t data_len = 0;
  size_t end = 0;  // offset just past the record
};

// Parses the record at `offset` of `buffer` (size `size`); every length must
// stay inside the buffer.
Status ParseBufferRecord(const uint8_t* buffer, size_t size, size_t offset, BufferRecord* r);

// ---- Record header building (writer side). ----
// Field name -> binary value. std::map keeps names sorted, the order ros_comm
// writes them in.
using HeaderFields = std::map<std::string, std::string>;

// Binary values of header fields.
std::string OpValue(Op op);
std::string U32Value(uint32_t value);
std::string U64Value(uint64_t value);
std::string TimeValue(RosTime t);

// The header bytes: { field_len u32le · name '=' value }* (no header_len prefix).
std::string BuildHeader(const HeaderFields& fields);
// Appends a whole record: header_len · header · data_len · data.
void AppendRecord(std::string* out, const HeaderFields& fields, std::string_view data);

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_FORMAT_H_
