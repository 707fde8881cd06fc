#ifndef TILTCAL_FUZZ_FUZZ_INPUT_FILE_H_
#define TILTCAL_FUZZ_FUZZ_INPUT_FILE_H_

// The readers under test take a path: each input is written to an anonymous
// in-memory file (memfd) and read back through /proc/self/fd/N, so fuzzing
// touches no disk.

#include <sys/mman.h>
#include <unistd.h>

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

}  // namespace tiltcal::fuzz

#endif  // TILTCAL_FUZZ_FUZZ_INPUT_FILE_H_
