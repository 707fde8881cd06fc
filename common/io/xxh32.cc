#include "common/io/xxh32.h"

#include <cstring>

namespace tiltcal {

namespace {

constexpr uint32_t kP1 = 0x9E3779B1u;
constexpr uint32_t kP2 = 0x85EBCA77u;
constexpr uint32_t kP3 = 0xC2B2AE3Du;
constexpr uint32_t kP4 = 0x27D4EB2Fu;
constexpr uint32_t kP5 = 0x165667B1u;

inline uint32_t Rotl(uint32_t x, int r) { return (x << r) | (x >> (32 - r)); }

// Little-endian u32 at `p` (unaligned).
inline uint32_t Load32(const unsigned char* p) {
  return uint32_t{p[0]} | (uint32_t{p[1]} << 8) | (uint32_t{p[2]} << 16) |
         (uint32_t{p[3]} << 24);
}

inline uint32_t Round(uint32_t acc, uint32_t lane) { return Rotl(acc + lane * kP2, 13) * kP1; }

// GCC's SLP vectoriser turns the four lanes into SSE2 code that emulates
// 32-bit multiplies with pmuludq + shuffles: 5x slower than scalar here.
#if defined(__GNUC__) && !defined(__clang__)
#define TILTCAL_SCALAR_LANES __attribute__((noinline, optimize("no-tree-slp-vectorize")))
#else
#define TILTCAL_SCALAR_LANES __attribute__((noinline))
#endif

// Consumes all whole 16-byte stripes of [p, p + size); returns the bytes used.
TILTCAL_SCALAR_LANES size_t Stripes(uint32_t v[4], const unsigned char* p, size_t size) {
  const size_t whole = size & ~size_t{15};
  uint32_t v1 = v[0], v2 = v[1], v3 = v[2], v4 = v[3];
  for (size_t i = 0; i < whole; i += 16) {
    v1 = Round(v1, Load32(p + i));
    v2 = Round(v2, Load32(p + i + 4));
    v3 = Round(v3, Load32(p + i + 8));
    v4 = Round(v4, Load32(p + i + 12));
  }
  v[0] = v1;
  v[1] = v2;
  v[2] = v3;
  v[3] = v4;
  return whole;
}

inline void Seed(uint32_t v[4], uint32_t seed) {
  v[0] = seed + kP1 + kP2;
  v[1] = seed + kP2;
  v[2] = seed;
  v[3] = seed - kP1;
}

// Length mix-in, remaining words and bytes (< 16 of them), avalanche.
inline uint32_t Finish(uint32_t acc, uint64_t total_size, const unsigned char* p, size_t rest) {
  acc += static_cast<uint32_t>(total_size);  // the length modulo 2^32
  while (rest >= 4) {
    acc = Rotl(acc + Load32(p) * kP3, 17) * kP4;
    p += 4;
    rest -= 4;
  }
  while (rest > 0) {
    acc = Rotl(acc + uint32_t{*p} * kP5, 11) * kP1;
    ++p;
    --rest;
  }
  acc ^= acc >> 15;
  acc *= kP2;
  acc ^= acc >> 13;
  acc *= kP3;
  acc ^= acc >> 16;
  return acc;
}

inline uint32_t Converge(const uint32_t v[4]) {
  return Rotl(v[0], 1) + Rotl(v[1], 7) + Rotl(v[2], 12) + Rotl(v[3], 18);
}

}  // namespace

uint32_t Xxh32(const void* data, size_t size, uint32_t seed) {
  const auto* p = static_cast<const unsigned char*>(data);
  uint32_t acc;
  size_t used = 0;
  if (size >= 16) {
    uint32_t v[4];
    Seed(v, seed);
    used = Stripes(v, p, size);
    acc = Converge(v);
  } else {
    acc = seed + kP5;
  }
  return Finish(acc, size, p + used, size - used);
}

void Xxh32State::Reset(uint32_t seed) {
  seed_ = seed;
  total_size_ = 0;
  buffered_ = 0;
  Seed(v_, seed);
}

void Xxh32State::Update(const void* data, size_t size) {
  if (size == 0) return;
  const auto* p = static_cast<const unsigned char*>(data);
  total_size_ += size;
  if (buffered_ > 0) {
    const size_t take = size < 16 - buffered_ ? size : 16 - buffered_;
    std::memcpy(buffer_ + buffered_, p, take);
    buffered_ += static_cast<uint32_t>(take);
    p += take;
    size -= take;
    if (buffered_ < 16) return;
    Stripes(v_, buffer_, 16);
    buffered_ = 0;
  }
  const size_t used = Stripes(v_, p, size);
  if (size > used) std::memcpy(buffer_, p + used, size - used);
  buffered_ = static_cast<uint32_t>(size - used);
}

uint32_t Xxh32State::Digest() const {
  const uint32_t acc = total_size_ >= 16 ? Converge(v_) : seed_ + kP5;
  return Finish(acc, total_size_, buffer_, buffered_);
}

}  // namespace tiltcal
