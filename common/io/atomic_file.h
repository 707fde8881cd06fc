#ifndef TILTCAL_COMMON_IO_ATOMIC_FILE_H_
#define TILTCAL_COMMON_IO_ATOMIC_FILE_H_

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"

namespace tiltcal {

class DirectFileOutput;

struct AtomicFileOptions {
  // Writes go past the page cache (DirectFileOutput, common/io/
  // direct_file_output.h): for large outputs no one reads right away.
  // WriteBehind() then has nothing to do.
  bool bypass_page_cache = false;
};

// Writes a file under a temporary name in the same directory
// (`<path>.tmp.<pid>`) and renames it to its final path on Commit(). Without
// a successful Commit() (error, early return, exception) the temporary file
// is removed, so a failed run never leaves a partial output that make could
// mistake for a finished one. Open() removes the temporaries of `path` left
// by processes that no longer run (killed runs).
class AtomicFile {
 public:
  AtomicFile();
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  Status Open(const std::string& path, const AtomicFileOptions& options = {});
  // Flushes, syncs and closes the temporary file, which stays under its
  // temporary name (see CommitTogether).
  Status Finish();
  // Finish() if not yet done, then renames the temporary file to the final
  // path.
  Status Commit();
  // Removes the temporary file; no-op after Commit().
  void Abandon();
  // Starts the device write of each completed kWriteBehindBytes window of
  // what has reached the kernel (Linux sync_file_range), and waits for the
  // window two before it. The device then writes while the rest is produced,
  // so Finish()'s sync waits for at most three windows, and a large output
  // keeps at most three windows of dirty pages. Call after writing; without
  // a new complete window it costs one lseek. Write errors still surface in
  // Finish().
  void WriteBehind();
  // Bytes from the start whose device write WriteBehind() has started.
  long long write_behind_bytes() const { return write_behind_end_; }

  std::FILE* file() { return file_; }
  const std::string& path() const { return path_; }
  const std::string& temp_path() const { return temp_path_; }

 private:
  std::string path_;
  std::string temp_path_;
  std::FILE* file_ = nullptr;
  // With bypass_page_cache: what file_ (a stdio stream over it) writes to.
  std::unique_ptr<DirectFileOutput> direct_;
  long long write_behind_end_ = 0;  // bytes whose device write has started
};

// The window of AtomicFile::WriteBehind.
inline constexpr long long kWriteBehindBytes = 8 << 20;

// Commits several outputs of one run so that a reader sees either all the
// old files or all the new ones. Every file is finished (synced under its
// temporary name); then a manifest `<path>.commit` listing every
// (temporary, final) pair is written beside each output; then the
// temporaries are renamed; then the manifests are removed. A process killed
// after the first manifest and before the last removal leaves manifests:
// RecordReader refuses a stream with a manifest beside it, and the writer's
// next run calls CompleteInterruptedCommit, which finishes the renames.
Status CommitTogether(const std::vector<AtomicFile*>& files);

// `path` + ".commit": the manifest of an interrupted CommitTogether.
std::string CommitManifestPath(const std::string& path);

// When `path` has a commit manifest beside it, completes that commit (renames
// every listed temporary that still exists, removes every listed manifest).
// No manifest: nothing to do.
Status CompleteInterruptedCommit(const std::string& path);

// An error when an output can certainly not be written at `path`: its
// directory does not exist (or is not a directory), or `path` is a
// directory. Stages call it before any work.
Status CheckOutputPath(const std::string& path);

// Writes `contents` to `path` atomically.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

// Reads a whole file. A path that is not a regular file (a directory, a
// device) is an error naming it.
Status ReadFileToString(const std::string& path, std::string* contents);

// Reads at most the first `max_bytes` bytes of a regular file.
Status ReadFileHead(const std::string& path, size_t max_bytes, std::string* contents);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_ATOMIC_FILE_H_
