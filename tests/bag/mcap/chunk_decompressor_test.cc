// The chunk decompressor on chunks made here with liblz4 and libzstd: real
// chunks decompress to their bytes; a chunk that declares more than its
// compressed bytes can hold is refused before the declared size is
// allocated (the process's peak memory does not grow by it).
#include "bag/mcap/chunk_decompressor.h"

#include <lz4frame.h>
#include <sys/resource.h>
#include <zstd.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::mcap {
namespace {

// Peak resident memory of this process so far, MB.
double PeakRssMb() {
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

std::vector<uint8_t> Records() {
  std::vector<uint8_t> records(5000);
  for (size_t i = 0; i < records.size(); ++i) records[i] = static_cast<uint8_t>(i % 7);
  return records;
}

std::vector<uint8_t> Lz4(const std::vector<uint8_t>& in) {
  std::vector<uint8_t> out(LZ4F_compressFrameBound(in.size(), nullptr));
  out.resize(LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr));
  return out;
}

std::vector<uint8_t> Zstd(const std::vector<uint8_t>& in) {
  std::vector<uint8_t> out(ZSTD_compressBound(in.size()));
  out.resize(ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3));
  return out;
}

ChunkRecord Chunk(const std::string& compression, const std::vector<uint8_t>& compressed,
                  uint64_t uncompressed_size) {
  ChunkRecord chunk;
  chunk.compression = compression;
  chunk.records = compressed.data();
  chunk.records_size = compressed.size();
  chunk.uncompressed_size = uncompressed_size;
  return chunk;
}

TEST(McapChunkDecompressor, RealChunksDecompressToTheirRecords) {
  const std::vector<uint8_t> records = Records();
  ChunkDecompressor decompressor;
  std::vector<uint8_t> out;
  for (const auto& [compression, bytes] :
       {std::pair<std::string, std::vector<uint8_t>>{"", records}, {"lz4", Lz4(records)},
        {"zstd", Zstd(records)}}) {
    ChunkRecord chunk = Chunk(compression, bytes, records.size());
    chunk.uncompressed_crc = Crc32(records.data(), records.size());
    ASSERT_TRUE(decompressor.Decompress(chunk, &out).ok()) << compression;
    EXPECT_EQ(out, records) << compression;
  }
}

TEST(McapChunkDecompressor, DeclaredSizeBeyondTheCompressedBytesIsRefusedBeforeAllocating) {
  const std::vector<uint8_t> records = Records();
  const std::vector<uint8_t> lz4 = Lz4(records);
  const std::vector<uint8_t> zstd = Zstd(records);
  const uint64_t declared = 300000000;  // 300 MB from a few hundred bytes
  struct Case {
    ChunkRecord chunk;
    std::string expected;
  };
  const Case cases[] = {
      {Chunk("", records, declared), "says uncompressed_size 300000000"},
      {Chunk("lz4", lz4, declared), "cannot decompress to the 300000000 bytes"},
      {Chunk("zstd", zstd, declared), "cannot decompress to the 300000000 bytes"},
      // Within zstd's ratio, but not the size its frame header declares.
      {Chunk("zstd", zstd, 2 * records.size()), "frame declares 5000 bytes"},
  };
  ChunkDecompressor decompressor(uint64_t{1} << 30);  // a limit above the declared sizes
  std::vector<uint8_t> out;
  const double rss_before_mb = PeakRssMb();
  for (const Case& c : cases) {
    const Status status = decompressor.Decompress(c.chunk, &out);
    ASSERT_FALSE(status.ok()) << c.expected;
    EXPECT_NE(status.message().find(c.expected), std::string::npos) << status.message();
  }
  EXPECT_LT(PeakRssMb() - rss_before_mb, 100.0);
}

}  // namespace
}  // namespace tiltcal::mcap
