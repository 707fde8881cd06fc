#ifndef TILTCAL_COMMON_IO_ATOMIC_FILE_H_
#define TILTCAL_COMMON_IO_ATOMIC_FILE_H_

#include <cstdio>
#include <string>

#include "common/status.h"

namespace tiltcal {

// Writes a file under a temporary name in the same directory and renames it
// to its final path on Commit(). Without a successful Commit() (error, early
// return, exception) the temporary file is removed, so a failed run never
// leaves a partial output that make could mistake for a finished one.
class AtomicFile {
 public:
  AtomicFile() = default;
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  Status Open(const std::string& path);
  // Flushes, syncs and renames the temporary file to the final path.
  Status Commit();
  // Removes the temporary file; no-op after Commit().
  void Abandon();

  std::FILE* file() { return file_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string temp_path_;
  std::FILE* file_ = nullptr;
};

// Writes `contents` to `path` atomically.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

// Reads a whole file.
Status ReadFileToString(const std::string& path, std::string* contents);

// Reads at most the first `max_bytes` bytes of a file.
Status ReadFileHead(const std::string& path, size_t max_bytes, std::string* contents);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_ATOMIC_FILE_H_
