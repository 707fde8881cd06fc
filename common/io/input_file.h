#ifndef TILTCAL_COMMON_IO_INPUT_FILE_H_
#define TILTCAL_COMMON_IO_INPUT_FILE_H_

// Every input file is a regular file (after symbolic links): a FIFO would
// block the open or the first read until some writer appears, a device such
// as /dev/zero never ends, a directory reads as empty. Both functions refuse
// anything else before a byte is read, with an error naming the path and
// what it is.

#include <cstdint>
#include <string>

#include "common/status.h"

namespace tiltcal {

// Opens `path` read-only and returns its descriptor and size. The open does
// not block on a FIFO (O_NONBLOCK, cleared again once the file is known to
// be regular). The caller closes *fd.
Status OpenInputFile(const std::string& path, int* fd, uint64_t* size);

// An error unless `path` is a regular file now (for libraries that open the
// file by name themselves: sqlite3, streams).
Status CheckInputFile(const std::string& path);

// What a file of mode `st_mode` (struct stat) is: "a FIFO", "a directory", ...
std::string FileKindName(unsigned st_mode);

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_INPUT_FILE_H_
