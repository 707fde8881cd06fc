#include "common/io/xxh32.h"

#include <lz4frame.h>

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace tiltcal {
namespace {

// Published XXH32 values (seed 0) of short strings.
TEST(Xxh32Test, KnownVectors) {
  EXPECT_EQ(Xxh32("", 0), 0x02CC5D05u);
  EXPECT_EQ(Xxh32("a", 1), 0x550D7456u);
  EXPECT_EQ(Xxh32("abc", 3), 0x32D153FFu);
}

std::vector<unsigned char> RandomBytes(size_t size, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<unsigned char> bytes(size);
  for (auto& b : bytes) b = static_cast<unsigned char>(rng());
  return bytes;
}

// liblz4's own XXH32, read back from the content checksum it appends to a frame
// (the last 4 bytes, little-endian): an independent implementation.
uint32_t Lz4ContentChecksum(const std::vector<unsigned char>& data) {
  LZ4F_preferences_t preferences = LZ4F_INIT_PREFERENCES;
  preferences.frameInfo.contentChecksumFlag = LZ4F_contentChecksumEnabled;
  std::vector<unsigned char> frame(LZ4F_compressFrameBound(data.size(), &preferences));
  const size_t size =
      LZ4F_compressFrame(frame.data(), frame.size(), data.data(), data.size(), &preferences);
  EXPECT_FALSE(LZ4F_isError(size));
  const unsigned char* c = frame.data() + size - 4;
  return uint32_t{c[0]} | (uint32_t{c[1]} << 8) | (uint32_t{c[2]} << 16) |
         (uint32_t{c[3]} << 24);
}

TEST(Xxh32Test, MatchesLiblz4ContentChecksum) {
  // Every tail length around the 16-byte stripes, and a few large sizes.
  std::vector<size_t> sizes;
  for (size_t s = 0; s <= 70; ++s) sizes.push_back(s);
  for (size_t s : {255u, 256u, 4097u, 65536u + 13u, 1000003u}) sizes.push_back(s);
  for (size_t size : sizes) {
    const auto data = RandomBytes(size, static_cast<uint32_t>(size) + 1);
    EXPECT_EQ(Xxh32(data.data(), data.size()), Lz4ContentChecksum(data)) << "size " << size;
  }
}

TEST(Xxh32Test, StreamingEqualsOneShotForAnySplit) {
  const auto data = RandomBytes(1000, 7);
  for (uint32_t seed : {0u, 1u, 0x9E3779B1u}) {
    const uint32_t expected = Xxh32(data.data(), data.size(), seed);
    for (size_t piece : {1u, 3u, 15u, 16u, 17u, 100u, 999u, 1000u}) {
      Xxh32State state(seed);
      for (size_t i = 0; i < data.size(); i += piece) {
        state.Update(data.data() + i, std::min(piece, data.size() - i));
      }
      EXPECT_EQ(state.Digest(), expected) << "seed " << seed << " piece " << piece;
    }
    // Short inputs take the seed + P5 start in both forms.
    Xxh32State shorter(seed);
    shorter.Update(data.data(), 9);
    EXPECT_EQ(shorter.Digest(), Xxh32(data.data(), 9, seed));
  }
}

TEST(Xxh32Test, SeedAndEveryByteMatter) {
  const auto data = RandomBytes(100, 3);
  EXPECT_NE(Xxh32(data.data(), data.size(), 0), Xxh32(data.data(), data.size(), 1));
  for (size_t i = 0; i < data.size(); ++i) {
    auto changed = data;
    changed[i] ^= 0x01;
    EXPECT_NE(Xxh32(changed.data(), changed.size()), Xxh32(data.data(), data.size())) << i;
  }
}

}  // namespace
}  // namespace tiltcal
