#ifndef TILTCAL_BAG_ROS1_CHUNK_CODEC_H_
#define TILTCAL_BAG_ROS1_CHUNK_CODEC_H_

// The compression of ROS1 chunk records (header field "compression"), both
// ways: the reader decompresses, the writer compresses, as ros_comm does.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include <lz4frame.h>

#include "common/status.h"

namespace tiltcal::ros1 {

// Compression of a ROS1 chunk record (header field "compression").
enum class ChunkCompression : uint8_t { kNone, kBz2, kLz4 };

// Parses "none" / "bz2" / "lz4"; false for anything else.
bool ParseChunkCompression(std::string_view name, ChunkCompression* compression);
// "none" / "bz2" / "lz4", the value of the chunk header field.
const char* ChunkCompressionName(ChunkCompression compression);

// Compresses the records of one chunk as ros_comm's rosbag does:
//   bz2: one bzip2 stream, block size 900k ("BZh9");
//   lz4: one LZ4 frame as roslz4 writes it (independent 1 MiB blocks, content
//        checksum, no content size, no block checksums: FLG 0x64, BD 0x60).
// kNone copies. The bytes depend only on `uncompressed`.
Status CompressChunk(ChunkCompression compression, const std::string& uncompressed,
                     std::string* compressed);

// Decompresses chunk data into a buffer of exactly the chunk's `size` bytes.
//   bz2: one bzip2 stream (libbz2 BZ2_bzBuffToBuffDecompress);
//   lz4: one LZ4 frame as written by roslz4 (liblz4 LZ4F_decompress; the
//        frame's content checksum is verified with the own XXH32, or by
//        liblz4 when the frame also has block checksums).
// The result must fill `dst_size` bytes exactly and consume all of `src`;
// otherwise the error says what differed (the caller adds file and chunk).
class ChunkDecompressor {
 public:
  ChunkDecompressor();
  ~ChunkDecompressor();
  ChunkDecompressor(const ChunkDecompressor&) = delete;
  ChunkDecompressor& operator=(const ChunkDecompressor&) = delete;

  Status Decompress(ChunkCompression compression, const uint8_t* src, size_t src_size,
                    uint8_t* dst, size_t dst_size);

 private:
  Status DecompressLz4(const uint8_t* src, size_t src_size, uint8_t* dst, size_t dst_size);
  LZ4F_dctx* lz4_ = nullptr;
};

}  // namespace tiltcal::ros1

#endif  // TILTCAL_BAG_ROS1_CHUNK_CODEC_H_
