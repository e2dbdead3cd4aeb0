#include "tessera/render/sampler.h"

#include "tessera/core/hash.h"

namespace tessera {

namespace sobol {
namespace {

uint32_t reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
  return (x >> 16) | (x << 16);
}

// Laine-Karras style permutation in bit-reversed space: each output bit depends only on the input
// bits below it, which is what makes it an Owen scramble once the bits are reversed back. The
// constants are Vegdahl's improved variant (2021) of Burley's hash; they mix better than the
// original Laine-Karras constants at equal cost.
uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}

}  // namespace

uint32_t sample(uint32_t index, int dim) {
  if (dim == 0) return reverse_bits(index);
  // Second Sobol dimension: direction numbers v_{k+1} = v_k ^ (v_k >> 1), v_1 = 1/2.
  uint32_t v = 0x80000000u, r = 0;
  for (; index; index >>= 1, v ^= v >> 1)
    if (index & 1u) r ^= v;
  return r;
}

uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

}  // namespace sobol

uint64_t Sampler::dim_hash(uint32_t dim) const {
  return hash_values(uint64_t(uint32_t(pixel_.x)), uint32_t(pixel_.y), dim, seed_);
}

float Sampler::next_1d() {
  uint32_t bits;
  if (type_ == SamplerType::Independent) {
    uint64_t h = hash_values(uint64_t(uint32_t(pixel_.x)), uint32_t(pixel_.y), index_, dim_, seed_);
    bits = uint32_t(h >> 32);
  } else {
    uint64_t h = dim_hash(dim_);
    // Shuffle the index (so each dimension and pixel walks the sequence in its own order), then
    // Owen-scramble the point: a padded, decorrelated stratified sequence per dimension.
    uint32_t i = sobol::nested_uniform_scramble(index_, uint32_t(h));
    bits = sobol::nested_uniform_scramble(sobol::sample(i, 0), uint32_t(h >> 32));
  }
  dim_ += 1;
  return bits_to_unit_float(bits);
}

Vec2 Sampler::next_2d() {
  uint32_t bx, by;
  if (type_ == SamplerType::Independent) {
    uint64_t h = hash_values(uint64_t(uint32_t(pixel_.x)), uint32_t(pixel_.y), index_, dim_, seed_);
    bx = uint32_t(h >> 32);
    by = uint32_t(h);
  } else {
    uint64_t h = dim_hash(dim_);
    uint64_t h2 = mix64(h ^ 0x5851f42d4c957f2dULL);
    // One shared index shuffle keeps the pair a (0,2)-sequence; separate scrambles per axis.
    uint32_t i = sobol::nested_uniform_scramble(index_, uint32_t(h));
    bx = sobol::nested_uniform_scramble(sobol::sample(i, 0), uint32_t(h >> 32));
    by = sobol::nested_uniform_scramble(sobol::sample(i, 1), uint32_t(h2));
  }
  dim_ += 2;
  return {bits_to_unit_float(bx), bits_to_unit_float(by)};
}

}  // namespace tessera
