#ifndef TILTCAL_BAG_MCAP_CHUNK_DECOMPRESSOR_H_
#define TILTCAL_BAG_MCAP_CHUNK_DECOMPRESSOR_H_

// The records of an MCAP chunk, decompressed: compression "" (stored), "lz4"
// (one LZ4 frame, liblz4; its own content checksum is skipped) or "zstd" (one
// zstd frame, libzstd). The result must be exactly the chunk's
// uncompressed_size, and match its uncompressed_crc when that is not 0.
// A declared size the compressed bytes cannot produce is refused before
// anything is allocated: beyond 256 bytes per byte for lz4 or 32768 for
// zstd, not the frame's own content size when it has one, or beyond the
// zstd frame's blocks times their maximum size, or beyond the decompressor's
// max_uncompressed_bytes (decode params max_decompressed_chunk_mib). Errors
// say what differed (the caller adds file and chunk offset).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "bag/mcap/format.h"
#include "common/status.h"

struct LZ4F_dctx_s;
struct ZSTD_DCtx_s;

namespace tiltcal::mcap {

class ChunkDecompressor {
 public:
  explicit ChunkDecompressor(uint64_t max_uncompressed_bytes = uint64_t{256} << 20);
  ~ChunkDecompressor();
  ChunkDecompressor(const ChunkDecompressor&) = delete;
  ChunkDecompressor& operator=(const ChunkDecompressor&) = delete;

  // Decompresses the records of `chunk` into *out (resized).
  Status Decompress(const ChunkRecord& chunk, std::vector<uint8_t>* out);

 private:
  // The reset lz4 context (created on first use).
  Status Lz4Context();
  // The frame's content size, when its header has one, must be the chunk's.
  Status CheckLz4ContentSize(const ChunkRecord& chunk);
  Status Lz4(const ChunkRecord& chunk, uint8_t* dst);
  Status Zstd(const ChunkRecord& chunk, uint8_t* dst);

  uint64_t max_uncompressed_bytes_;
  LZ4F_dctx_s* lz4_ = nullptr;
  ZSTD_DCtx_s* zstd_ = nullptr;
};

}  // namespace tiltcal::mcap

#endif  // TILTCAL_BAG_MCAP_CHUNK_DECOMPRESSOR_H_
