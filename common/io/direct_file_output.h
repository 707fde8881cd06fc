#ifndef TILTCAL_COMMON_IO_DIRECT_FILE_OUTPUT_H_
#define TILTCAL_COMMON_IO_DIRECT_FILE_OUTPUT_H_

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace tiltcal {

// Alignment of the buffers, file offsets and lengths of direct writes: the
// page size, a multiple of every common device's logical block size.
inline constexpr size_t kDirectWriteAlignment = 4096;
// Bytes gathered before one direct write.
inline constexpr size_t kDirectWriteBufferBytes = 4 << 20;
// Buffers: one being filled while the others are written.
inline constexpr size_t kDirectWriteBuffers = 3;

// Writes a new file past the page cache (Linux O_DIRECT): bytes gather in
// aligned buffers that a background thread writes straight from user memory
// to the device, so the kernel neither copies them into page-cache pages nor
// allocates, tracks and writes back those pages. For a large output that no
// one reads again soon this saves the kernel's copy and page handling (0.3-0.9
// CPU s per GB, bench/decode/README.md) and keeps the page cache for the
// inputs; a later reader of the file reads it from the device.
//
// The last partial block is written through the page cache (O_DIRECT
// cleared), so the file has exactly the bytes written. A file system that
// refuses O_DIRECT at open (tmpfs before Linux 6.6) or on a write (an alignment it does not
// accept) gets the same bytes through the page cache instead.
class DirectFileOutput {
 public:
  DirectFileOutput() = default;
  ~DirectFileOutput();
  DirectFileOutput(const DirectFileOutput&) = delete;
  DirectFileOutput& operator=(const DirectFileOutput&) = delete;

  // Creates (truncates) `path`, with O_DIRECT when `direct` (and the file
  // system accepts it). False with errno set when it cannot.
  bool Open(const std::string& path, bool direct = true);
  // Copies `size` bytes into the current buffer; a full buffer goes to the
  // writing thread. False after any failed write (errno of that write).
  bool Write(const void* data, size_t size);
  // Writes everything, syncs the file to the device and closes it. False
  // with errno of the first failure.
  bool Close();
  // Stops writing and closes the file (its contents are undefined).
  void Abandon();

  // Whether the file was opened with O_DIRECT (false: the page cache took
  // every write).
  bool direct() const { return direct_; }

 private:
  struct Buffer {
    char* data = nullptr;
    size_t size = 0;       // bytes filled
    long long offset = 0;  // file offset of data[0]
  };
  void WriteQueued();
  bool WriteAt(const char* data, size_t size, long long offset);
  void Stop();
  bool ClearDirect();

  int fd_ = -1;
  bool direct_ = false;
  std::vector<std::unique_ptr<char, void (*)(void*)>> storage_;
  Buffer current_;            // being filled by Write(); data null: none
  long long next_offset_ = 0; // file offset of the next byte written
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<char*> free_;
  std::deque<Buffer> queue_;  // full buffers, in file order
  bool stopping_ = false;
  int error_ = 0;             // errno of the first failed write
  std::thread thread_;
};

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_DIRECT_FILE_OUTPUT_H_
