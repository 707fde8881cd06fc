#include "common/io/direct_file_output.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>

namespace tiltcal {

DirectFileOutput::~DirectFileOutput() { Abandon(); }

bool DirectFileOutput::Open(const std::string& path, bool direct) {
  Abandon();
  constexpr int kFlags = O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC;
  fd_ = direct ? ::open(path.c_str(), kFlags | O_DIRECT, 0666) : -1;
  direct_ = fd_ >= 0;
  if (fd_ < 0 && (!direct || errno == EINVAL)) fd_ = ::open(path.c_str(), kFlags, 0666);
  if (fd_ < 0) return false;
  if (storage_.empty()) {
    for (size_t i = 0; i < kDirectWriteBuffers; ++i) {
      void* data = std::aligned_alloc(kDirectWriteAlignment, kDirectWriteBufferBytes);
      if (data == nullptr) {
        Abandon();
        errno = ENOMEM;
        return false;
      }
      storage_.emplace_back(static_cast<char*>(data), std::free);
    }
  }
  free_.clear();
  for (const auto& buffer : storage_) free_.push_back(buffer.get());
  queue_.clear();
  current_ = Buffer();
  next_offset_ = 0;
  error_ = 0;
  stopping_ = false;
  thread_ = std::thread([this] { WriteQueued(); });
  return true;
}

bool DirectFileOutput::Write(const void* data, size_t size) {
  const char* bytes = static_cast<const char*>(data);
  while (size > 0) {
    if (current_.data == nullptr) {
      std::unique_lock<std::mutex> lock(mutex_);
      changed_.wait(lock, [this] { return !free_.empty() || error_ != 0; });
      if (error_ != 0) {
        errno = error_;
        return false;
      }
      current_.data = free_.back();
      free_.pop_back();
      current_.size = 0;
      current_.offset = next_offset_;
    }
    const size_t piece = std::min(size, kDirectWriteBufferBytes - current_.size);
    std::memcpy(current_.data + current_.size, bytes, piece);
    current_.size += piece;
    next_offset_ += static_cast<long long>(piece);
    bytes += piece;
    size -= piece;
    if (current_.size == kDirectWriteBufferBytes) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        queue_.push_back(current_);
      }
      current_ = Buffer();
      changed_.notify_all();
    }
  }
  return true;
}

void DirectFileOutput::WriteQueued() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping and drained
    const Buffer buffer = queue_.front();
    queue_.pop_front();
    const bool skip = error_ != 0;
    lock.unlock();
    const int error = skip || WriteAt(buffer.data, buffer.size, buffer.offset) ? 0 : errno;
    lock.lock();
    if (error != 0 && error_ == 0) error_ = error;
    free_.push_back(buffer.data);
    changed_.notify_all();
  }
}

bool DirectFileOutput::ClearDirect() {
  const int flags = ::fcntl(fd_, F_GETFL);
  if (flags < 0 || ::fcntl(fd_, F_SETFL, flags & ~O_DIRECT) != 0) return false;
  direct_ = false;
  return true;
}

bool DirectFileOutput::WriteAt(const char* data, size_t size, long long offset) {
  while (size > 0) {
    const ssize_t written = ::pwrite(fd_, data, size, static_cast<off_t>(offset));
    if (written < 0) {
      if (errno == EINTR) continue;
      // The file system accepted O_DIRECT at open but not this write (its
      // alignment is larger): the rest goes through the page cache.
      if (errno == EINVAL && direct_ && ClearDirect()) continue;
      return false;
    }
    if (written == 0) {
      errno = EIO;
      return false;
    }
    data += written;
    size -= static_cast<size_t>(written);
    offset += written;
  }
  return true;
}

void DirectFileOutput::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool DirectFileOutput::Close() {
  if (fd_ < 0) {
    errno = EBADF;
    return false;
  }
  Stop();  // writes what is queued
  int error = error_;
  if (error == 0 && current_.data != nullptr && current_.size > 0) {
    // Whole blocks directly, then the partial block through the page cache.
    const size_t whole = current_.size & ~(kDirectWriteAlignment - 1);
    const size_t rest = current_.size - whole;
    if (!WriteAt(current_.data, whole, current_.offset) ||
        (rest > 0 && direct_ && !ClearDirect()) ||
        !WriteAt(current_.data + whole, rest, current_.offset + static_cast<long long>(whole))) {
      error = errno;
    }
  }
  current_ = Buffer();
  if (error == 0 && ::fsync(fd_) != 0) error = errno;
  if (::close(fd_) != 0 && error == 0) error = errno;
  fd_ = -1;
  errno = error;
  return error == 0;
}

void DirectFileOutput::Abandon() {
  if (thread_.joinable()) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (error_ == 0) error_ = ECANCELED;  // the thread skips what is queued
    }
    Stop();
  }
  current_ = Buffer();
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

}  // namespace tiltcal
