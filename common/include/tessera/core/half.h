// IEEE 754 binary16 ("half") to float, for textures kept in half precision. Every half is exactly
// representable as a float, so both paths below give the same bits for every non-NaN half (F16C
// also quiets signalling NaNs; texture loading replaces NaNs anyway). The F16C instruction is used
// only when the build's ISA has it (the avx2 baseline does not imply it), the portable path
// otherwise. Conversion the other way (with rounding) happens at load time only and uses Imath.
#pragma once

#include <cstdint>
#include <cstring>

#if defined(__F16C__)
#include <immintrin.h>
#endif

namespace tessera {

/// Branch-light scalar conversion: shifting the exponent and mantissa into place and multiplying
/// by 2^112 rebias normals and subnormals alike (the product is exact, as long as float
/// subnormals are not flushed: the renderer never sets DAZ); infinities and NaNs get the all-ones
/// float exponent.
inline float half_to_float_portable(uint16_t h) {
  const uint32_t magnitude = uint32_t(h & 0x7fffu) << 13;
  float f;
  std::memcpy(&f, &magnitude, sizeof f);
  f *= 0x1p112f;
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  if ((h & 0x7c00u) == 0x7c00u) bits = 0x7f800000u | magnitude;  // inf / NaN (payload kept)
  bits |= uint32_t(h & 0x8000u) << 16;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

inline float half_to_float(uint16_t h) {
#if defined(__F16C__)
  return _cvtsh_ss(h);
#else
  return half_to_float_portable(h);
#endif
}

}  // namespace tessera
