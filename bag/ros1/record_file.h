#ifndef TILTCAL_BAG_ROS1_RECORD_FILE_H_
#define TILTCAL_BAG_ROS1_RECORD_FILE_H_

// A ROS1 bag file opened for reading records at byte offsets. The file is
// read with pread(), so that reads from several threads need no lock;
// nothing is memory-mapped.

#include <cstddef>
#include <cstdint>
#include <string>

#include "bag/ros1/format.h"
#include "common/status.h"

namespace tiltcal::ros1 {

class RecordFile {
 public:
  RecordFile() = default;
  ~RecordFile();
  RecordFile(const RecordFile&) = delete;
  RecordFile& operator=(const RecordFile&) = delete;

  // Opens `path` (a regular file) read-only.
  Status Open(const std::string& path);

  const std::string& path() const { return path_; }
  uint64_t size() const { return size_; }

  // "<path>: record at byte <pos>: <what>".
  Status Error(uint64_t pos, const std::string& what) const;
  // Reads `size` bytes at `pos` into `dst`; an error when they run past the
  // end of the file.
  Status ReadAt(uint64_t pos, size_t size, void* dst) const;
  // Reads the record header at `pos`: header fields into *header (views into
  // *buffer), the data position and length. The record must fit in the file.
  Status ReadRecordHeaderAt(uint64_t pos, std::string* buffer, RecordHeader* header,
                            uint64_t* data_pos, uint32_t* data_len) const;

 private:
  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0;
};

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_RECORD_FILE_H_
