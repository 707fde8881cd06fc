#include "bag/ros1/record_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "common/io/input_file.h"

namespace tiltcal::ros1 {
namespace {

// Real record headers are tens of bytes; a larger length is a corrupt one,
// refused before it allocates.
constexpr uint32_t kMaxHeaderBytes = 1 << 20;

}  // namespace

RecordFile::~RecordFile() {
  if (fd_ >= 0) ::close(fd_);
}

Status RecordFile::Open(const std::string& path) {
  path_ = path;
  return OpenInputFile(path, &fd_, &size_);
}

Status RecordFile::Error(uint64_t pos, const std::string& what) const {
  return Status::Error(path_ + ": record at byte " + std::to_string(pos) + ": " + what);
}

Status RecordFile::ReadAt(uint64_t pos, size_t size, void* dst) const {
  if (pos > size_ || size > size_ - pos) {
    return Status::Error(path_ + ": read of " + std::to_string(size) + " bytes at byte " +
                         std::to_string(pos) + " runs past the end of the file (" +
                         std::to_string(size_) + " bytes; truncated?)");
  }
  auto* out = static_cast<char*>(dst);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::pread(fd_, out + done, size - done, static_cast<off_t>(pos + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      return Status::Error(path_ + ": read error at byte " + std::to_string(pos + done) + ": " +
                           (n < 0 ? std::strerror(errno) : "unexpected end of file"));
    }
    done += static_cast<size_t>(n);
  }
  return Status::Ok();
}

Status RecordFile::ReadRecordHeaderAt(uint64_t pos, std::string* buffer, RecordHeader* header,
                                      uint64_t* data_pos, uint32_t* data_len) const {
  if (pos > size_ || size_ - pos < 8) {
    return Error(pos, "record runs past the end of the file (" + std::to_string(size_) +
                          " bytes; truncated?)");
  }
  uint32_t header_len = 0;
  TILTCAL_RETURN_IF_ERROR(ReadAt(pos, 4, &header_len));
  if (header_len > kMaxHeaderBytes) {
    return Error(pos, "header length " + std::to_string(header_len) + " is implausible (> " +
                          std::to_string(kMaxHeaderBytes) + " bytes; corrupt bag?)");
  }
  if (header_len > size_ - pos - 8) {
    return Error(pos, "header length " + std::to_string(header_len) +
                          " runs past the end of the file (" + std::to_string(size_) +
                          " bytes; truncated?)");
  }
  buffer->resize(header_len + 4);
  TILTCAL_RETURN_IF_ERROR(ReadAt(pos + 4, header_len + 4, buffer->data()));
  *data_len = LoadU32Le(buffer->data() + header_len);
  *data_pos = pos + 8 + header_len;
  if (*data_len > size_ - *data_pos) {
    return Error(pos, "data length " + std::to_string(*data_len) +
                          " runs past the end of the file (" + std::to_string(size_) +
                          " bytes; truncated?)");
  }
  Status status = header->Parse(buffer->data(), header_len);
  if (!status.ok()) return Error(pos, status.message());
  return Status::Ok();
}

}  // namespace tiltcal::ros1
