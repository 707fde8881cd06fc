#ifndef TILTCAL_COMMON_IO_XXH32_H_
#define TILTCAL_COMMON_IO_XXH32_H_

// XXH32, the 32-bit xxHash (the checksum of LZ4 frames: header checksum,
// block checksums and the content checksum), written from the xxHash
// specification (doc/xxhash_spec.md, "XXH32 algorithm description"):
//   4 accumulators v1..v4 over 16-byte stripes of four little-endian u32 lanes,
//     round(acc, lane) = rotl32(acc + lane * P2, 13) * P1,
//   seeded v1 = seed + P1 + P2, v2 = seed + P2, v3 = seed, v4 = seed - P1;
//   inputs < 16 bytes start from acc = seed + P5 instead of the converged
//   rotl(v1,1) + rotl(v2,7) + rotl(v3,12) + rotl(v4,18);
//   then acc += total length, the remaining 4-byte words
//     acc = rotl32(acc + word * P3, 17) * P4, the remaining bytes
//     acc = rotl32(acc + byte * P5, 11) * P1, and the avalanche
//     acc ^= acc >> 15; acc *= P2; acc ^= acc >> 13; acc *= P3; acc ^= acc >> 16.
// Plain scalar code: the four independent accumulators already keep a
// superscalar core busy (several GB/s), unlike SSE2 code that has to emulate
// 32-bit multiplies.

#include <cstddef>
#include <cstdint>

namespace tiltcal {

// XXH32 of `size` bytes at `data`.
uint32_t Xxh32(const void* data, size_t size, uint32_t seed = 0);

// XXH32 of data that arrives in pieces; Digest() equals Xxh32() of all the
// pieces concatenated, whatever the split.
class Xxh32State {
 public:
  explicit Xxh32State(uint32_t seed = 0) { Reset(seed); }
  void Reset(uint32_t seed = 0);
  void Update(const void* data, size_t size);
  uint32_t Digest() const;

 private:
  uint64_t total_size_ = 0;
  uint32_t v_[4] = {0, 0, 0, 0};
  uint32_t seed_ = 0;
  unsigned char buffer_[16] = {};  // a partial stripe
  uint32_t buffered_ = 0;
};

}  // namespace tiltcal

#endif  // TILTCAL_COMMON_IO_XXH32_H_
