#include "bag/mcap/chunk_decompressor.h"

#include <lz4frame.h>
// ZSTD_decompressBound (libzstd >= 1.4.0; exported by the shared library).
#define ZSTD_STATIC_LINKING_ONLY
#include <zstd.h>

#include <algorithm>
#include <cstring>

namespace tiltcal::mcap {

namespace {

// No chunk of a sane recording is this large; refuse before allocating.
constexpr uint64_t kMaxChunkBytes = uint64_t{4} << 30;
// The most output one input byte can give: an LZ4 sequence adds at most 255
// bytes of match per length byte; a zstd block of at most 128 KiB takes at
// least 4 bytes (3 of header, 1 of an RLE block). A chunk that declares more
// cannot be valid, and is refused before its declared size is allocated.
constexpr uint64_t kLz4MaxRatio = 256;
constexpr uint64_t kZstdMaxRatio = 32768;

// An error when `compressed` bytes of `codec` cannot hold `uncompressed`.
Status CheckRatio(const char* codec, uint64_t compressed, uint64_t uncompressed,
                  uint64_t max_ratio) {
  if (uncompressed / max_ratio > compressed) {
    return Status::Error(std::string(codec) + " chunk of " + std::to_string(compressed) +
                         " bytes cannot decompress to the " + std::to_string(uncompressed) +
                         " bytes it declares (at most " + std::to_string(max_ratio) +
                         " bytes per compressed byte)");
  }
  return Status::Ok();
}

}  // namespace

ChunkDecompressor::ChunkDecompressor(uint64_t max_uncompressed_bytes)
    : max_uncompressed_bytes_(std::min(max_uncompressed_bytes, kMaxChunkBytes)) {}

ChunkDecompressor::~ChunkDecompressor() {
  if (lz4_ != nullptr) LZ4F_freeDecompressionContext(lz4_);
  if (zstd_ != nullptr) ZSTD_freeDCtx(zstd_);
}

Status ChunkDecompressor::Decompress(const ChunkRecord& chunk, std::vector<uint8_t>* out) {
  if (chunk.uncompressed_size > max_uncompressed_bytes_) {
    return Status::Error("chunk uncompressed_size " + std::to_string(chunk.uncompressed_size) +
                         " bytes is beyond the limit of " +
                         std::to_string(max_uncompressed_bytes_) +
                         " bytes for one decompressed chunk (decode params "
                         "max_decompressed_chunk_mib)");
  }
  if (chunk.compression != "" && chunk.compression != "lz4" && chunk.compression != "zstd") {
    return Status::Error("unknown chunk compression '" + chunk.compression +
                         "' (known: none, lz4, zstd)");
  }
  // Declared sizes are checked against the compressed bytes before the
  // output is allocated.
  if (chunk.compression.empty()) {
    if (chunk.records_size != chunk.uncompressed_size) {
      return Status::Error("uncompressed chunk of " + std::to_string(chunk.records_size) +
                           " bytes says uncompressed_size " +
                           std::to_string(chunk.uncompressed_size));
    }
    out->resize(chunk.uncompressed_size);
    if (chunk.records_size > 0) std::memcpy(out->data(), chunk.records, chunk.records_size);
  } else if (chunk.compression == "lz4") {
    TILTCAL_RETURN_IF_ERROR(
        CheckRatio("lz4", chunk.records_size, chunk.uncompressed_size, kLz4MaxRatio));
    TILTCAL_RETURN_IF_ERROR(CheckLz4ContentSize(chunk));
    out->resize(chunk.uncompressed_size);
    TILTCAL_RETURN_IF_ERROR(Lz4(chunk, out->data()));
  } else {
    TILTCAL_RETURN_IF_ERROR(
        CheckRatio("zstd", chunk.records_size, chunk.uncompressed_size, kZstdMaxRatio));
    // The frame's own content size when it has one, else its blocks times
    // their maximum size (ZSTD_decompressBound), must allow the chunk's.
    const unsigned long long declared =
        ZSTD_getFrameContentSize(chunk.records, chunk.records_size);
    if (declared == ZSTD_CONTENTSIZE_ERROR) {
      return Status::Error("zstd chunk's frame header does not parse");
    }
    if (declared != ZSTD_CONTENTSIZE_UNKNOWN && declared != chunk.uncompressed_size) {
      return Status::Error("zstd chunk's frame declares " + std::to_string(declared) +
                           " bytes, the chunk says " + std::to_string(chunk.uncompressed_size));
    }
    const unsigned long long bound = ZSTD_decompressBound(chunk.records, chunk.records_size);
    if (bound == ZSTD_CONTENTSIZE_ERROR || bound < chunk.uncompressed_size) {
      return Status::Error("zstd chunk's frames " +
                           (bound == ZSTD_CONTENTSIZE_ERROR
                                ? std::string("do not parse")
                                : "hold at most " + std::to_string(bound) + " bytes") +
                           ", the chunk says " + std::to_string(chunk.uncompressed_size));
    }
    out->resize(chunk.uncompressed_size);
    TILTCAL_RETURN_IF_ERROR(Zstd(chunk, out->data()));
  }
  if (chunk.uncompressed_crc != 0) {
    const uint32_t crc = Crc32(out->data(), out->size());
    if (crc != chunk.uncompressed_crc) {
      return Status::Error("chunk CRC mismatch (records have CRC-32 " + std::to_string(crc) +
                           ", the chunk says " + std::to_string(chunk.uncompressed_crc) + ")");
    }
  }
  return Status::Ok();
}

Status ChunkDecompressor::Lz4Context() {
  if (lz4_ == nullptr) {
    const size_t rc = LZ4F_createDecompressionContext(&lz4_, LZ4F_VERSION);
    if (LZ4F_isError(rc)) return Status::Error("lz4: cannot create a decompression context");
  }
  LZ4F_resetDecompressionContext(lz4_);
  return Status::Ok();
}

Status ChunkDecompressor::CheckLz4ContentSize(const ChunkRecord& chunk) {
  TILTCAL_RETURN_IF_ERROR(Lz4Context());
  LZ4F_frameInfo_t info = {};
  size_t header_bytes = static_cast<size_t>(chunk.records_size);
  const size_t rc = LZ4F_getFrameInfo(lz4_, &info, chunk.records, &header_bytes);
  if (LZ4F_isError(rc)) {
    return Status::Error(std::string("lz4 chunk's frame header does not parse: ") +
                         LZ4F_getErrorName(rc));
  }
  if (info.contentSize != 0 && info.contentSize != chunk.uncompressed_size) {
    return Status::Error("lz4 chunk's frame declares " + std::to_string(info.contentSize) +
                         " bytes, the chunk says " + std::to_string(chunk.uncompressed_size));
  }
  return Status::Ok();
}

Status ChunkDecompressor::Lz4(const ChunkRecord& chunk, uint8_t* dst) {
  TILTCAL_RETURN_IF_ERROR(Lz4Context());
  size_t src_used = static_cast<size_t>(chunk.records_size);
  size_t dst_used = static_cast<size_t>(chunk.uncompressed_size);
  // The frame's own content checksum is not verified: the chunk's CRC-32 of
  // the same bytes is (Decompress), and liblz4's XXH32 is slow here.
  LZ4F_decompressOptions_t options = {};
  options.skipChecksums = 1;
  const size_t rc = LZ4F_decompress(lz4_, dst, &dst_used, chunk.records, &src_used, &options);
  if (LZ4F_isError(rc)) {
    return Status::Error(std::string("lz4 chunk does not decompress: ") + LZ4F_getErrorName(rc));
  }
  if (rc != 0 || dst_used != chunk.uncompressed_size || src_used != chunk.records_size) {
    return Status::Error("lz4 chunk decompresses to " + std::to_string(dst_used) +
                         " bytes from " + std::to_string(src_used) + " of " +
                         std::to_string(chunk.records_size) + ", the chunk says " +
                         std::to_string(chunk.uncompressed_size) + (rc != 0 ? " (frame incomplete)" : ""));
  }
  return Status::Ok();
}

Status ChunkDecompressor::Zstd(const ChunkRecord& chunk, uint8_t* dst) {
  if (zstd_ == nullptr) zstd_ = ZSTD_createDCtx();
  if (zstd_ == nullptr) return Status::Error("zstd: cannot create a decompression context");
  const size_t n = ZSTD_decompressDCtx(zstd_, dst, chunk.uncompressed_size, chunk.records,
                                       chunk.records_size);
  if (ZSTD_isError(n)) {
    return Status::Error(std::string("zstd chunk does not decompress: ") + ZSTD_getErrorName(n));
  }
  if (n != chunk.uncompressed_size) {
    return Status::Error("zstd chunk decompresses to " + std::to_string(n) +
                         " bytes, the chunk says " + std::to_string(chunk.uncompressed_size));
  }
  return Status::Ok();
}

}  // namespace tiltcal::mcap
