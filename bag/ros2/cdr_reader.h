#ifndef TILTCAL_BAG_ROS2_CDR_READER_H_
#define TILTCAL_BAG_ROS2_CDR_READER_H_

// A bounds-checked reader of one ROS 2 message serialized as plain CDR
// (XCDR1, the rmw default):
//   bytes 0-1  encapsulation kind: 00 00 big endian (CDR_BE), 00 01 little
//              endian (CDR_LE); any other kind (parameter lists, XCDR2) is
//              an error;
//   bytes 2-3  options (ignored);
//   payload    primitives aligned to their own size (1, 2, 4, 8 bytes)
//              relative to the payload start, i.e. byte 4 of the message;
//              string = u32 length counting a terminating NUL, the bytes,
//              the NUL; T[] = u32 count + elements; T[N] = N elements.
// The writer may pad the message to a multiple of 4 bytes, so up to 3 bytes
// after the last field are accepted by ExpectEnd().

#include <cstddef>
#include <cstdint>
#include <string>

#include "common/status.h"

namespace tiltcal::ros2 {

class CdrReader {
 public:
  // Reads the encapsulation header of `size` bytes at `data` (not copied).
  Status Open(const uint8_t* data, size_t size);

  bool big_endian() const { return big_endian_; }

  // Each read names its field in the error of a message that runs short.
  Status U8(const char* what, uint8_t* v);
  Status Bool(const char* what, bool* v);
  Status U32(const char* what, uint32_t* v);
  Status I32(const char* what, int32_t* v);
  Status U64(const char* what, uint64_t* v);
  Status F32(const char* what, float* v);
  Status F64s(const char* what, double* v, size_t n);
  Status String(const char* what, std::string* s);
  // A uint8[] sequence: its count, then a view of its bytes (no copy).
  Status ByteSequence(const char* what, const uint8_t** bytes, uint32_t* size);
  // An error when more than alignment padding (3 bytes) follows the last field.
  Status ExpectEnd(const char* type) const;

 private:
  // Skips padding to a multiple of `alignment` (relative to the payload),
  // then takes `n` bytes.
  Status Take(size_t alignment, size_t n, const char* what, const uint8_t** out);

  const uint8_t* payload_ = nullptr;
  size_t size_ = 0;  // payload bytes
  size_t pos_ = 0;   // within the payload
  bool big_endian_ = false;
};

}  // namespace tiltcal::ros2

#endif  // TILTCAL_BAG_ROS2_CDR_READER_H_
