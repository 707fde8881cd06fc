#include "common/io/lz4_stream.h"

#include <lz4frame.h>

#include <algorithm>
#include <cstring>

#include "common/io/xxh32.h"

namespace tiltcal {

namespace {
constexpr size_t kInputBufferBytes = 1 << 16;
constexpr size_t kMaxWriteBytes = kLz4FrameBlockBytes;
}  // namespace

Lz4FrameOutput::Lz4FrameOutput(std::FILE* file, const Lz4FrameOptions& options)
    : file_(file), options_(options) {
  // Frame header (LZ4 frame format): magic (4 bytes), FLG, BD, HC where
  // FLG = version 01 (bits 7-6) | block independence (bit 5) | content
  // checksum (bit 2), BD = block maximum size id << 4 (5: 256 KiB) and
  // HC = (XXH32(FLG BD, seed 0) >> 8) & 0xFF.
  constexpr size_t kHeaderBytes = 7;
  constexpr unsigned char kContentChecksumBit = 0x04;
  if (!options_.compress_blocks) {
    out_.resize(16);  // the header; at Close() the end mark and the checksum
    std::memcpy(out_.data(), kLz4FrameMagic, sizeof(kLz4FrameMagic));
    out_[4] = static_cast<char>(0x60 | (options_.content_checksum ? kContentChecksumBit : 0));
    out_[5] = static_cast<char>(0x50);
    out_[6] = static_cast<char>((Xxh32(out_.data() + 4, 2) >> 8) & 0xFF);
    failed_ = !Flush(kHeaderBytes);
    return;
  }
  if (LZ4F_isError(LZ4F_createCompressionContext(&context_, LZ4F_VERSION))) {
    failed_ = true;
    return;
  }
  // liblz4 is asked for a frame without content checksum; the checksum is
  // computed here with the own XXH32 (liblz4's is ~2x slower) and announced in
  // the frame descriptor, so the file is the standard frame liblz4 would
  // write with contentChecksumFlag on (`lz4 -dc` verifies it).
  LZ4F_preferences_t preferences = LZ4F_INIT_PREFERENCES;
  preferences.frameInfo.blockSizeID = LZ4F_max256KB;
  preferences.frameInfo.contentChecksumFlag = LZ4F_noContentChecksum;
  // Fast mode (acceleration 4) on independent blocks: on the decode stage's
  // scans (float columns, ratio ~1.21) 0.6x the compression CPU of level 0
  // for 1.7 % more bytes (bench/decode/README.md).
  preferences.compressionLevel = -4;
  preferences.frameInfo.blockMode = LZ4F_blockIndependent;
  out_.resize(LZ4F_compressBound(kMaxWriteBytes, &preferences) + LZ4F_HEADER_SIZE_MAX);
  const size_t header = LZ4F_compressBegin(context_, out_.data(), out_.size(), &preferences);
  if (LZ4F_isError(header) || header != kHeaderBytes || (out_[4] & kContentChecksumBit) != 0) {
    failed_ = true;
    return;
  }
  if (options_.content_checksum) {
    out_[4] = static_cast<char>(out_[4] | kContentChecksumBit);
    out_[6] = static_cast<char>((Xxh32(out_.data() + 4, 2) >> 8) & 0xFF);
  }
  failed_ = !Flush(header);
}

Lz4FrameOutput::~Lz4FrameOutput() {
  if (context_ != nullptr) LZ4F_freeCompressionContext(context_);
}

bool Lz4FrameOutput::Flush(size_t bytes) {
  return std::fwrite(out_.data(), 1, bytes, file_) == bytes;
}

// A stored block: its size (little-endian u32) with bit 31 set, then the bytes.
bool Lz4FrameOutput::WriteStoredBlock(const char* data, size_t size) {
  const uint32_t word = static_cast<uint32_t>(size) | 0x80000000u;
  char header[4];
  for (int i = 0; i < 4; ++i) header[i] = static_cast<char>((word >> (8 * i)) & 0xFF);
  return std::fwrite(header, 1, sizeof(header), file_) == sizeof(header) &&
         std::fwrite(data, 1, size, file_) == size;
}

bool Lz4FrameOutput::Write(const void* buffer, int size) {
  const char* data = static_cast<const char*>(buffer);
  while (!failed_ && size > 0) {
    const size_t piece = std::min<size_t>(size, kMaxWriteBytes);
    if (options_.content_checksum) checksum_.Update(data, piece);
    if (options_.compress_blocks) {
      const size_t written =
          LZ4F_compressUpdate(context_, out_.data(), out_.size(), data, piece, nullptr);
      failed_ = LZ4F_isError(written) || !Flush(written);
    } else {
      failed_ = !WriteStoredBlock(data, piece);
    }
    data += piece;
    size -= static_cast<int>(piece);
  }
  return !failed_;
}

bool Lz4FrameOutput::Close() {
  if (failed_) return false;
  // Last block and the end mark (a zero block size word), then the content
  // checksum (little-endian).
  size_t written = 0;
  if (options_.compress_blocks) {
    written = LZ4F_compressEnd(context_, out_.data(), out_.size(), nullptr);
    if (LZ4F_isError(written)) {
      failed_ = true;
      return false;
    }
  } else {
    for (int i = 0; i < 4; ++i) out_[written++] = 0;
  }
  if (written + 4 > out_.size()) {
    failed_ = true;
    return false;
  }
  if (options_.content_checksum) {
    const uint32_t digest = checksum_.Digest();
    for (int i = 0; i < 4; ++i) out_[written++] = static_cast<char>((digest >> (8 * i)) & 0xFF);
  }
  failed_ = !Flush(written);
  return !failed_;
}

Lz4FrameInput::Lz4FrameInput(std::FILE* file) : file_(file), in_(kInputBufferBytes) {
  if (LZ4F_isError(LZ4F_createDecompressionContext(&context_, LZ4F_VERSION))) {
    error_ = "cannot create an LZ4 decompression context";
  }
}

Lz4FrameInput::~Lz4FrameInput() { LZ4F_freeDecompressionContext(context_); }

int Lz4FrameInput::Read(void* buffer, int size) {
  if (!error_.empty()) return -1;
  char* out = static_cast<char*>(buffer);
  size_t produced_total = 0;
  while (produced_total == 0 && !frame_done_) {
    if (in_begin_ == in_end_) {
      in_begin_ = 0;
      in_end_ = std::fread(in_.data(), 1, in_.size(), file_);
      if (in_end_ == 0) {
        error_ = std::ferror(file_) ? "read error" : "LZ4 frame is truncated";
        return -1;
      }
    }
    size_t produced = static_cast<size_t>(size) - produced_total;
    size_t consumed = in_end_ - in_begin_;
    const size_t hint = LZ4F_decompress(context_, out + produced_total, &produced,
                                        in_.data() + in_begin_, &consumed, nullptr);
    if (LZ4F_isError(hint)) {
      error_ = std::string("LZ4 frame is corrupt: ") + LZ4F_getErrorName(hint);
      return -1;
    }
    in_begin_ += consumed;
    produced_total += produced;
    frame_done_ = hint == 0;
  }
  return static_cast<int>(produced_total);  // 0 only after the frame's end mark
}

}  // namespace tiltcal
