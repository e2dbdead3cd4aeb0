// Unit vectors in a few bits: the octahedral map (Cigolle et al. 2014, "A Survey of Efficient
// Representations for Independent Unit Vectors"), quantised to `bits` per coordinate.
#pragma once

#include "tessera/core/vec.h"

#include <cmath>
#include <cstdint>

namespace tessera::octahedral {

inline float sign_not_zero(float v) { return v >= 0.f ? 1.f : -1.f; }

/// Quantises unit `d` to two `bits`-bit coordinates, packed as (u << bits) | v.
inline uint32_t encode(Vec3 d, int bits) {
  const float l1 = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
  float u = d.x / l1, v = d.y / l1;
  if (d.z < 0.f) {
    const float fu = (1.f - std::abs(v)) * sign_not_zero(u), fv = (1.f - std::abs(u)) * sign_not_zero(v);
    u = fu, v = fv;
  }
  const float scale = float((1u << bits) - 1);
  auto q = [&](float x) { return uint32_t(std::lround((std::fmin(std::fmax(x, -1.f), 1.f) * 0.5f + 0.5f) * scale)); };
  return (q(u) << bits) | q(v);
}

inline Vec3 decode(uint32_t packed, int bits) {
  const uint32_t mask = (1u << bits) - 1;
  const float scale = 1.f / float(mask);
  const float u = float(packed >> bits) * scale * 2.f - 1.f, v = float(packed & mask) * scale * 2.f - 1.f;
  Vec3 d(u, v, 1.f - std::abs(u) - std::abs(v));
  if (d.z < 0.f) {
    const float fx = (1.f - std::abs(v)) * sign_not_zero(u), fy = (1.f - std::abs(u)) * sign_not_zero(v);
    d.x = fx, d.y = fy;
  }
  return normalize(d);
}

}  // namespace tessera::octahedral
