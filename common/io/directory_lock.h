#ifndef TILTCAL_COMMON_IO_DIRECTORY_LOCK_H_
#define TILTCAL_COMMON_IO_DIRECTORY_LOCK_H_

#include <ostream>
#include <string>

#include "common/status.h"

namespace tiltcal {

// An exclusive advisory lock (flock(2)) on a directory, held until the
// object is destroyed: one writer at a time for the outputs in it. The same
// lock `flock DIR …` takes from the shell (Makefile.pipeline locks a
// dataset's out/ folder with it), and nothing is left on disk. A lock held
// by another process is waited for, with one line on `log` saying so.
class DirectoryLock {
 public:
  DirectoryLock() = default;
  DirectoryLock(const DirectoryLock&) = delete;
  DirectoryLock& operator=(const DirectoryLock&) = delete;
  ~DirectoryLock();

  // Locks `dir`; `what` names the waiting program in the log line
  // ("tiltcal_decode: waiting for another run writing into DIR").
  Status Acquire(const std::string& dir, const std::string& what, std::ostream* log);

 private:
  int fd_ = -1;
};

// The directory an output file is written into, as a canonical path (one
// spelling per directory, so that a process never locks one twice).
std::string OutputDirectory(const std::string& path);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_DIRECTORY_LOCK_H_
