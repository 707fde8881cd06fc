#include "common/io/directory_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

namespace tiltcal {

DirectoryLock::~DirectoryLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the descriptor releases the lock
}

Status DirectoryLock::Acquire(const std::string& dir, const std::string& what,
                              std::ostream* log) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return Status::Error(dir + ": cannot lock: " + std::strerror(errno));
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    if (errno != EWOULDBLOCK) {
      const std::string error = std::strerror(errno);
      ::close(fd);
      return Status::Error(dir + ": cannot lock: " + error);
    }
    if (log != nullptr) {
      *log << what << ": waiting for another run writing into " << dir << "\n" << std::flush;
    }
    int status;
    while ((status = ::flock(fd, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (status != 0) {
      const std::string error = std::strerror(errno);
      ::close(fd);
      return Status::Error(dir + ": cannot lock: " + error);
    }
  }
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
  return Status::Ok();
}

std::string OutputDirectory(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::error_code error;
  const std::filesystem::path canonical =
      std::filesystem::weakly_canonical(parent.empty() ? "." : parent, error);
  if (error) return parent.empty() ? "." : parent.string();
  return canonical.string();
}

}  // namespace tiltcal
