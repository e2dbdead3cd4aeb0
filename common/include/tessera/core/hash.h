// Integer hashing and a small counter-based RNG. A sample's value must depend only on
// (pixel, sample index, dimension, seed), so randomness comes from hashing those, not from state.
#pragma once

#include <cstdint>

namespace tessera {

/// 64-bit finaliser (splitmix64 / MurmurHash3 fmix64 family).
constexpr uint64_t mix64(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

constexpr uint64_t hash_combine(uint64_t a, uint64_t b) {
  return mix64(a ^ (b + 0x9e3779b97f4a7c15ULL + (a << 6) + (a >> 2)));
}

template <typename... Ts>
constexpr uint64_t hash_values(uint64_t first, Ts... rest) {
  uint64_t h = mix64(first + 0x9e3779b97f4a7c15ULL);
  ((h = hash_combine(h, uint64_t(rest))), ...);
  return h;
}

/// Maps 32 random bits to a float in [0, 1) (24-bit mantissa: never rounds up to 1).
constexpr float bits_to_unit_float(uint32_t bits) { return float(bits >> 8) * 0x1p-24f; }

/// PCG32 (O'Neill), for tests and tools that want a stream of numbers.
class Pcg32 {
 public:
  explicit Pcg32(uint64_t seed = 0x853c49e6748fea9bULL, uint64_t seq = 0xda3e39cb94b95bdbULL) {
    state_ = 0;
    inc_ = (seq << 1u) | 1u;
    next_u32();
    state_ += seed;
    next_u32();
  }
  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }
  float next_float() { return bits_to_unit_float(next_u32()); }

 private:
  uint64_t state_, inc_;
};

}  // namespace tessera
