// lz4 chunks as roslz4 writes them (one LZ4 frame, content checksum, no
// block checksums) and with block checksums: decoded exactly, and every
// single corrupted byte of the frame is reported as an error.
#include "bag/ros1/chunk_codec.h"

#include <lz4frame.h>

#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace tiltcal::ros1 {
namespace {

// Half random bytes (stored as literals), half repeated words (matches).
std::vector<uint8_t> ChunkContent(size_t size, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> data(size);
  for (size_t i = 0; i < size; ++i) {
    data[i] = (i / 64) % 2 == 0 ? static_cast<uint8_t>(rng()) : static_cast<uint8_t>(i % 7);
  }
  return data;
}

std::vector<uint8_t> Lz4Frame(const std::vector<uint8_t>& content, bool block_checksums,
                              bool content_checksum) {
  LZ4F_preferences_t preferences = LZ4F_INIT_PREFERENCES;
  preferences.frameInfo.contentChecksumFlag =
      content_checksum ? LZ4F_contentChecksumEnabled : LZ4F_noContentChecksum;
  preferences.frameInfo.blockChecksumFlag =
      block_checksums ? LZ4F_blockChecksumEnabled : LZ4F_noBlockChecksum;
  std::vector<uint8_t> frame(LZ4F_compressFrameBound(content.size(), &preferences));
  const size_t size = LZ4F_compressFrame(frame.data(), frame.size(), content.data(),
                                         content.size(), &preferences);
  EXPECT_FALSE(LZ4F_isError(size));
  frame.resize(size);
  return frame;
}

TEST(ChunkDecompressor, DecodesFramesWithAndWithoutChecksums) {
  ChunkDecompressor decompressor;
  for (bool block : {false, true}) {
    for (bool content : {false, true}) {
      for (size_t size : {size_t{0}, size_t{1}, size_t{100}, size_t{300000}}) {
        const auto data = ChunkContent(size, static_cast<uint32_t>(size));
        const auto frame = Lz4Frame(data, block, content);
        std::vector<uint8_t> out(size + 1);
        const Status status = decompressor.Decompress(ChunkCompression::kLz4, frame.data(),
                                                      frame.size(), out.data(), size);
        ASSERT_TRUE(status.ok()) << status.message() << " block " << block << " content "
                                 << content << " size " << size;
        out.resize(size);
        EXPECT_TRUE(out == data);
      }
    }
  }
}

// Flips every byte of the frame in turn (roslz4 layout, then with block
// checksums too): each must fail, and the decompressor must decode the
// intact frame again afterwards.
TEST(ChunkDecompressor, EverySingleCorruptedByteIsAnError) {
  ChunkDecompressor decompressor;
  for (bool block : {false, true}) {
    const auto data = ChunkContent(3000, 5);
    const auto frame = Lz4Frame(data, block, /*content_checksum=*/true);
    std::vector<uint8_t> out(data.size());
    for (size_t i = 0; i < frame.size(); ++i) {
      auto bad = frame;
      bad[i] ^= 0x20;
      const Status status = decompressor.Decompress(ChunkCompression::kLz4, bad.data(),
                                                    bad.size(), out.data(), out.size());
      EXPECT_FALSE(status.ok()) << "byte " << i << " of " << frame.size() << " block " << block;
    }
    ASSERT_TRUE(decompressor
                    .Decompress(ChunkCompression::kLz4, frame.data(), frame.size(), out.data(),
                                out.size())
                    .ok());
    EXPECT_TRUE(out == data);
  }
}

// A changed literal decodes fine; only the content checksum can catch it.
TEST(ChunkDecompressor, ContentChecksumCatchesChangedLiteral) {
  std::mt19937 rng(9);
  std::vector<uint8_t> data(1000);
  for (auto& b : data) b = static_cast<uint8_t>(rng());  // incompressible: a stored block
  auto frame = Lz4Frame(data, false, true);
  ASSERT_EQ(frame.size(), 7u + 4u + 1000u + 4u + 4u);  // header, block size, data, end, checksum
  frame[7 + 4 + 500] ^= 0x01;
  ChunkDecompressor decompressor;
  std::vector<uint8_t> out(data.size());
  const Status status = decompressor.Decompress(ChunkCompression::kLz4, frame.data(),
                                                frame.size(), out.data(), out.size());
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("checksum"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace tiltcal::ros1
