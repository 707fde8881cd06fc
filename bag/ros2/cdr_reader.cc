#include "bag/ros2/cdr_reader.h"

#include <cstring>

namespace tiltcal::ros2 {

namespace {

constexpr size_t kEncapsulationBytes = 4;

// The value of `N` bytes at `p` in the message's byte order.
template <typename T>
T Load(const uint8_t* p, bool big_endian) {
  uint8_t bytes[sizeof(T)];
  std::memcpy(bytes, p, sizeof(T));
  if (big_endian) {  // the host is little endian (x86-64, aarch64)
    for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  }
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

}  // namespace

Status CdrReader::Open(const uint8_t* data, size_t size) {
  if (size < kEncapsulationBytes) {
    return Status::Error("CDR message of " + std::to_string(size) +
                         " bytes has no 4-byte encapsulation header");
  }
  if (data[0] != 0 || data[1] > 1) {
    return Status::Error("CDR encapsulation kind " + std::to_string(data[0]) + "." +
                         std::to_string(data[1]) +
                         " is not plain CDR (00 00 big endian or 00 01 little endian)");
  }
  big_endian_ = data[1] == 0;
  payload_ = data + kEncapsulationBytes;
  size_ = size - kEncapsulationBytes;
  pos_ = 0;
  return Status::Ok();
}

Status CdrReader::Take(size_t alignment, size_t n, const char* what, const uint8_t** out) {
  const size_t aligned = (pos_ + alignment - 1) / alignment * alignment;
  if (aligned > size_ || n > size_ - aligned) {
    return Status::Error(std::string("message runs past its end: ") + what + " needs " +
                         std::to_string(n) + " bytes at payload byte " + std::to_string(aligned) +
                         ", the payload has " + std::to_string(size_));
  }
  *out = payload_ + aligned;
  pos_ = aligned + n;
  return Status::Ok();
}

Status CdrReader::U8(const char* what, uint8_t* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Take(1, 1, what, &p));
  *v = *p;
  return Status::Ok();
}

Status CdrReader::Bool(const char* what, bool* v) {
  uint8_t b = 0;
  TILTCAL_RETURN_IF_ERROR(U8(what, &b));
  *v = b != 0;  // as the ROS 1 decoder: any non-zero byte is true
  return Status::Ok();
}

Status CdrReader::U32(const char* what, uint32_t* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Take(4, 4, what, &p));
  *v = Load<uint32_t>(p, big_endian_);
  return Status::Ok();
}

Status CdrReader::I32(const char* what, int32_t* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Take(4, 4, what, &p));
  *v = Load<int32_t>(p, big_endian_);
  return Status::Ok();
}

Status CdrReader::U64(const char* what, uint64_t* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Take(8, 8, what, &p));
  *v = Load<uint64_t>(p, big_endian_);
  return Status::Ok();
}

Status CdrReader::F32(const char* what, float* v) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Take(4, 4, what, &p));
  *v = Load<float>(p, big_endian_);
  return Status::Ok();
}

Status CdrReader::F64s(const char* what, double* v, size_t n) {
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Take(8, 8 * n, what, &p));
  for (size_t i = 0; i < n; ++i) v[i] = Load<double>(p + 8 * i, big_endian_);
  return Status::Ok();
}

Status CdrReader::String(const char* what, std::string* s) {
  uint32_t length = 0;
  TILTCAL_RETURN_IF_ERROR(U32(what, &length));
  const uint8_t* p = nullptr;
  TILTCAL_RETURN_IF_ERROR(Take(1, length, what, &p));
  // The length counts the terminating NUL; 0 is tolerated as an empty string.
  if (length > 0 && p[length - 1] != 0) {
    return Status::Error(std::string(what) + " (a string of " + std::to_string(length) +
                         " bytes) does not end in NUL");
  }
  s->assign(reinterpret_cast<const char*>(p), length > 0 ? length - 1 : 0);
  return Status::Ok();
}

Status CdrReader::ByteSequence(const char* what, const uint8_t** bytes, uint32_t* size) {
  TILTCAL_RETURN_IF_ERROR(U32(what, size));
  return Take(1, *size, what, bytes);
}

Status CdrReader::ExpectEnd(const char* type) const {
  if (size_ - pos_ > 3) {
    return Status::Error("message has " + std::to_string(size_ - pos_) +
                         " bytes after the end of the " + type + " message (payload of " +
                         std::to_string(size_) + " bytes): another message type?");
  }
  return Status::Ok();
}

}  // namespace tiltcal::ros2
