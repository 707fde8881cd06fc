#include "bag/ros1/chunk_codec.h"

#include <bzlib.h>
#include <lz4frame.h>

#include <cstring>
#include <string>

#include "common/io/xxh32.h"

namespace tiltcal::ros1 {

bool ParseChunkCompression(std::string_view name, ChunkCompression* compression) {
  if (name == "none") {
    *compression = ChunkCompression::kNone;
  } else if (name == "bz2") {
    *compression = ChunkCompression::kBz2;
  } else if (name == "lz4") {
    *compression = ChunkCompression::kLz4;
  } else {
    return false;
  }
  return true;
}

const char* ChunkCompressionName(ChunkCompression compression) {
  switch (compression) {
    case ChunkCompression::kNone: return "none";
    case ChunkCompression::kBz2: return "bz2";
    case ChunkCompression::kLz4: return "lz4";
  }
  return "?";
}

namespace {

const char* Bz2ErrorName(int code) {
  switch (code) {
    case BZ_DATA_ERROR: return "corrupt data (CRC or stream error)";
    case BZ_DATA_ERROR_MAGIC: return "no bzip2 magic";
    case BZ_UNEXPECTED_EOF: return "compressed data ends early";
    case BZ_OUTBUFF_FULL: return "decompresses to more than the chunk size";
    case BZ_MEM_ERROR: return "out of memory";
    case BZ_PARAM_ERROR: return "bad parameters";
    case BZ_CONFIG_ERROR: return "libbz2 misconfigured";
    default: return "error";
  }
}

// roslz4's frame: block independence, 1 MiB blocks (id 6), content checksum,
// no content size, no block checksums (FLG 0x64, BD 0x60).
Status CompressLz4(const std::string& in, std::string* out) {
  LZ4F_preferences_t prefs = LZ4F_INIT_PREFERENCES;
  prefs.frameInfo.blockSizeID = LZ4F_max1MB;
  prefs.frameInfo.blockMode = LZ4F_blockIndependent;
  prefs.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
  prefs.frameInfo.contentSize = 0;
  prefs.frameInfo.blockChecksumFlag = LZ4F_noBlockChecksum;
  prefs.compressionLevel = 0;
  out->resize(LZ4F_compressFrameBound(in.size(), &prefs));
  const size_t n = LZ4F_compressFrame(out->data(), out->size(), in.data(), in.size(), &prefs);
  if (LZ4F_isError(n)) {
    return Status::Error(std::string("lz4 compression failed: ") + LZ4F_getErrorName(n));
  }
  out->resize(n);
  return Status::Ok();
}

// One bzip2 stream, block size 900k ("BZh9"), as ros_comm's bz2 stream.
Status CompressBz2(const std::string& in, std::string* out) {
  unsigned int size = static_cast<unsigned int>(in.size() + in.size() / 100 + 600);
  out->resize(size);
  const int rc = BZ2_bzBuffToBuffCompress(out->data(), &size, const_cast<char*>(in.data()),
                                          static_cast<unsigned int>(in.size()), 9, 0, 30);
  if (rc != BZ_OK) return Status::Error("bz2 compression failed, code " + std::to_string(rc));
  out->resize(size);
  return Status::Ok();
}

}  // namespace

Status CompressChunk(ChunkCompression compression, const std::string& uncompressed,
                     std::string* compressed) {
  switch (compression) {
    case ChunkCompression::kNone:
      *compressed = uncompressed;
      return Status::Ok();
    case ChunkCompression::kBz2: return CompressBz2(uncompressed, compressed);
    case ChunkCompression::kLz4: return CompressLz4(uncompressed, compressed);
  }
  return Status::Error("unknown chunk compression");
}

ChunkDecompressor::ChunkDecompressor() = default;

ChunkDecompressor::~ChunkDecompressor() {
  if (lz4_ != nullptr) LZ4F_freeDecompressionContext(lz4_);
}

Status ChunkDecompressor::Decompress(ChunkCompression compression, const uint8_t* src,
                                     size_t src_size, uint8_t* dst, size_t dst_size) {
  switch (compression) {
    case ChunkCompression::kNone:
      if (src_size != dst_size) {
        return Status::Error("uncompressed chunk has " + std::to_string(src_size) +
                             " data bytes but declares size " + std::to_string(dst_size));
      }
      if (src != dst && src_size > 0) std::memcpy(dst, src, src_size);
      return Status::Ok();
    case ChunkCompression::kBz2: {
      if (src_size > UINT32_MAX || dst_size > UINT32_MAX) {
        return Status::Error("bz2 chunk larger than 4 GiB");
      }
      unsigned int produced = static_cast<unsigned int>(dst_size);
      const int rc = BZ2_bzBuffToBuffDecompress(
          reinterpret_cast<char*>(dst), &produced,
          const_cast<char*>(reinterpret_cast<const char*>(src)),
          static_cast<unsigned int>(src_size), /*small=*/0, /*verbosity=*/0);
      if (rc != BZ_OK) {
        return Status::Error(std::string("bz2 decompression failed: ") + Bz2ErrorName(rc) +
                             " (libbz2 code " + std::to_string(rc) + ")");
      }
      if (produced != dst_size) {
        return Status::Error("bz2 data decompresses to " + std::to_string(produced) +
                             " bytes, chunk size is " + std::to_string(dst_size));
      }
      return Status::Ok();
    }
    case ChunkCompression::kLz4:
      return DecompressLz4(src, src_size, dst, dst_size);
  }
  return Status::Error("unknown chunk compression");
}

Status ChunkDecompressor::DecompressLz4(const uint8_t* src, size_t src_size, uint8_t* dst,
                                        size_t dst_size) {
  if (lz4_ == nullptr) {
    const LZ4F_errorCode_t rc = LZ4F_createDecompressionContext(&lz4_, LZ4F_VERSION);
    if (LZ4F_isError(rc)) {
      lz4_ = nullptr;
      return Status::Error(std::string("cannot create an LZ4 context: ") + LZ4F_getErrorName(rc));
    }
  }
  // The whole frame is decoded into one buffer that stays put, so liblz4 may
  // decode straight into it (stableDst) instead of through its own window.
  LZ4F_decompressOptions_t options = {};
  options.stableDst = 1;
  // Frame descriptor flags (LZ4 frame format: FLG is the byte after the
  // 4-byte magic; bit 4 = block checksums, bit 2 = content checksum). roslz4
  // writes a content checksum and no block checksums: liblz4 is told to skip
  // it and the content is hashed here with the faster own XXH32 after the
  // frame decoded completely. Frames with block checksums keep liblz4's checks.
  const bool own_content_checksum = src_size >= 4 + 3 + 4 && (src[4] & 0x04) != 0 &&
                                    (src[4] & 0x10) == 0;
  options.skipChecksums = own_content_checksum ? 1 : 0;
  LZ4F_resetDecompressionContext(lz4_);  // skipChecksums sticks for a whole frame
  size_t consumed = 0;
  size_t produced = 0;
  size_t hint = 1;
  // One ROS1 lz4 chunk is one LZ4 frame; loop until the frame ends (hint 0).
  while (hint != 0) {
    size_t in = src_size - consumed;
    size_t out = dst_size - produced;
    if (in == 0) {
      LZ4F_resetDecompressionContext(lz4_);
      return Status::Error("lz4 frame ends early: " + std::to_string(produced) + " of " +
                           std::to_string(dst_size) + " bytes decoded from all " +
                           std::to_string(src_size) + " compressed bytes");
    }
    hint = LZ4F_decompress(lz4_, dst + produced, &out, src + consumed, &in, &options);
    if (LZ4F_isError(hint)) {
      LZ4F_resetDecompressionContext(lz4_);
      return Status::Error(std::string("lz4 decompression failed: ") + LZ4F_getErrorName(hint) +
                           " (at compressed byte " + std::to_string(consumed) + ")");
    }
    consumed += in;
    produced += out;
    if (hint != 0 && in == 0 && out == 0) {
      LZ4F_resetDecompressionContext(lz4_);
      return Status::Error("lz4 data decompresses to more than the chunk size " +
                           std::to_string(dst_size));
    }
  }
  if (produced != dst_size) {
    return Status::Error("lz4 data decompresses to " + std::to_string(produced) +
                         " bytes, chunk size is " + std::to_string(dst_size));
  }
  if (consumed != src_size) {
    return Status::Error("lz4 frame ends " + std::to_string(src_size - consumed) +
                         " bytes before the chunk data ends");
  }
  if (own_content_checksum) {
    // The frame consumed all of src, so its last 4 bytes are the content
    // checksum: XXH32 (seed 0) of the decompressed bytes, little-endian.
    const uint8_t* c = src + src_size - 4;
    const uint32_t stored = uint32_t{c[0]} | (uint32_t{c[1]} << 8) | (uint32_t{c[2]} << 16) |
                            (uint32_t{c[3]} << 24);
    const uint32_t computed = Xxh32(dst, dst_size);
    if (computed != stored) {
      return Status::Error("lz4 content checksum mismatch (frame says " +
                           std::to_string(stored) + ", data hashes to " +
                           std::to_string(computed) + ")");
    }
  }
  return Status::Ok();
}

}  // namespace tiltcal::ros1
