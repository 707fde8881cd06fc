#ifndef TILTCAL_COMMON_IO_LZ4_STREAM_H_
#define TILTCAL_COMMON_IO_LZ4_STREAM_H_

#include <cstdio>
#include <string>
#include <vector>

#include <google/protobuf/io/zero_copy_stream_impl_lite.h>

#include "common/io/xxh32.h"

struct LZ4F_cctx_s;
struct LZ4F_dctx_s;

namespace tiltcal {

// First four bytes of every LZ4 frame (0x184D2204, little-endian).
inline constexpr unsigned char kLz4FrameMagic[4] = {0x04, 0x22, 0x4D, 0x18};

// Block size of the frames Lz4FrameOutput writes (LZ4F_max256KB). Writes of
// exactly this size are compressed without an extra copy.
inline constexpr size_t kLz4FrameBlockBytes = 256 * 1024;

// How Lz4FrameOutput builds its frame. Every combination is a standard LZ4
// frame (independent blocks of at most kLz4FrameBlockBytes) that `lz4 -dc`
// and liblz4 decode.
struct Lz4FrameOptions {
  // true: blocks compressed by liblz4 in fast mode (acceleration 4); false:
  // every block stored as is (block size word with its high bit set, LZ4
  // frame format), no compression work, the frame ~1.2x larger on float
  // point columns.
  bool compress_blocks = true;
  // The frame's content checksum (XXH32 of all content, after the end mark),
  // verified by every reader.
  bool content_checksum = true;
};

// Writes everything written into one standard LZ4 frame on `file` (the
// content checksum, when on, computed with the own XXH32), so `lz4 -dc` gives
// back the plain bytes and, with the checksum, detects corruption.
// Close() writes the end mark; the caller owns and closes `file`.
class Lz4FrameOutput : public google::protobuf::io::CopyingOutputStream {
 public:
  explicit Lz4FrameOutput(std::FILE* file, const Lz4FrameOptions& options = {});
  ~Lz4FrameOutput() override;
  bool Write(const void* buffer, int size) override;
  bool Close();

 private:
  bool Flush(size_t bytes);
  bool WriteStoredBlock(const char* data, size_t size);
  std::FILE* file_;
  Lz4FrameOptions options_;
  LZ4F_cctx_s* context_ = nullptr;
  Xxh32State checksum_;  // of everything written: the frame's content checksum
  std::vector<char> out_;
  bool failed_ = false;
};

// Reads the decompressed content of one LZ4 frame from `file`. A frame that
// ends before its end mark, or fails its checksum, sets error() instead of
// looking like a clean end of data.
class Lz4FrameInput : public google::protobuf::io::CopyingInputStream {
 public:
  explicit Lz4FrameInput(std::FILE* file);
  ~Lz4FrameInput() override;
  int Read(void* buffer, int size) override;
  const std::string& error() const { return error_; }

 private:
  std::FILE* file_;
  LZ4F_dctx_s* context_ = nullptr;
  std::vector<char> in_;
  size_t in_begin_ = 0;
  size_t in_end_ = 0;
  bool frame_done_ = false;
  std::string error_;
};

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_LZ4_STREAM_H_
