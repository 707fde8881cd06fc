#ifndef TILTCAL_FUZZ_FUZZ_INPUT_FILE_H_
#define TILTCAL_FUZZ_FUZZ_INPUT_FILE_H_

// The readers under test take a path: each input is written to an anonymous
// in-memory file (memfd) and read back through /proc/self/fd/N, so fuzzing
// touches no disk. libsqlite3 resolves symbolic links before it opens a
// file, which /proc/self/fd/N of a memfd defeats; FuzzInputNamedFile writes
// the input to a named file in /dev/shm (memory as well) instead.

#include <sys/mman.h>
#include <unistd.h>

#include <cstdio>

#include <cstddef>
#include <cstdint>
#include <string>

namespace tiltcal::fuzz {

class FuzzInputFile {
 public:
  FuzzInputFile(const uint8_t* data, size_t size) : fd_(::memfd_create("tiltcal_fuzz", 0)) {
    size_t written = 0;
    while (fd_ >= 0 && written < size) {
      const ssize_t n = ::write(fd_, data + written, size - written);
      if (n <= 0) break;
      written += static_cast<size_t>(n);
    }
  }
  ~FuzzInputFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  FuzzInputFile(const FuzzInputFile&) = delete;
  FuzzInputFile& operator=(const FuzzInputFile&) = delete;

  bool ok() const { return fd_ >= 0; }
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

// The input as /dev/shm/tiltcal_fuzz_<pid><suffix>, removed by the destructor.
class FuzzInputNamedFile {
 public:
  FuzzInputNamedFile(const uint8_t* data, size_t size, const std::string& suffix)
      : path_("/dev/shm/tiltcal_fuzz_" + std::to_string(::getpid()) + suffix) {
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    ok_ = f != nullptr && std::fwrite(data, 1, size, f) == size;
    if (f != nullptr && std::fclose(f) != 0) ok_ = false;
  }
  ~FuzzInputNamedFile() { std::remove(path_.c_str()); }
  FuzzInputNamedFile(const FuzzInputNamedFile&) = delete;
  FuzzInputNamedFile& operator=(const FuzzInputNamedFile&) = delete;

  bool ok() const { return ok_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  bool ok_ = false;
};

}  // namespace tiltcal::fuzz

#endif  // TILTCAL_FUZZ_FUZZ_INPUT_FILE_H_
