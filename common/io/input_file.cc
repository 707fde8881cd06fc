#include "common/io/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace tiltcal {

namespace {

Status NotRegular(const std::string& path, unsigned st_mode) {
  return Status::Error(path + ": " + FileKindName(st_mode) +
                       ", not a regular file; inputs are read from regular files only");
}

}  // namespace

std::string FileKindName(unsigned st_mode) {
  if (S_ISFIFO(st_mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(st_mode)) return "a character device";
  if (S_ISBLK(st_mode)) return "a block device";
  if (S_ISSOCK(st_mode)) return "a socket";
  if (S_ISDIR(st_mode)) return "a directory";
  if (S_ISREG(st_mode)) return "a regular file";
  return "a special file";
}

Status OpenInputFile(const std::string& path, int* fd, uint64_t* size) {
  *fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (*fd < 0) return Status::Error(path + ": cannot open: " + std::strerror(errno));
  struct stat st;
  if (::fstat(*fd, &st) != 0) {
    const int error = errno;
    ::close(*fd);
    *fd = -1;
    return Status::Error(path + ": cannot stat: " + std::strerror(error));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(*fd);
    *fd = -1;
    return NotRegular(path, st.st_mode);
  }
  const int flags = ::fcntl(*fd, F_GETFL);
  if (flags >= 0) (void)::fcntl(*fd, F_SETFL, flags & ~O_NONBLOCK);
  *size = static_cast<uint64_t>(st.st_size);
  return Status::Ok();
}

Status CheckInputFile(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    return Status::Error(path + ": cannot open: " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode)) return NotRegular(path, st.st_mode);
  return Status::Ok();
}

}  // namespace tiltcal
