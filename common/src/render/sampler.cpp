#include "tessera/render/sampler.h"

#include "tessera/core/hash.h"

#include <array>

namespace tessera {

namespace sobol {
namespace {

inline uint32_t reverse_bits(uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
}

// Laine-Karras style permutation in bit-reversed space: each output bit depends only on the input
// bits below it, which is what makes it an Owen scramble once the bits are reversed back. The
// constants are Vegdahl's improved variant (2021) of Burley's hash; they mix better than the
// original Laine-Karras constants at equal cost.
inline uint32_t laine_karras_permutation(uint32_t x, uint32_t seed) {
  x ^= x * 0x3d20adeau;
  x += seed;
  x *= (seed >> 16) | 1u;
  x ^= x * 0x05526c56u;
  x ^= x * 0x53a22864u;
  return x;
}

// Second Sobol dimension: direction numbers v_1 = 1/2, v_{k+1} = v_k ^ (v_k >> 1) (the Pascal
// matrix mod 2). Shuffled indices use all 32 bits, so the matrix-vector product is done a byte
// at a time through tables rather than bit by bit. With `reversed`, the tables hold the products'
// bit reversals (what the Owen scramble works on), which saves a reversal per sample.
constexpr uint32_t reverse_bits_slow(uint32_t x) {
  uint32_t r = 0;
  for (int b = 0; b < 32; ++b) r |= ((x >> b) & 1u) << (31 - b);
  return r;
}
constexpr std::array<std::array<uint32_t, 256>, 4> make_dim1_tables(bool reversed) {
  std::array<uint32_t, 32> v{};
  v[0] = 0x80000000u;
  for (int k = 1; k < 32; ++k) v[size_t(k)] = v[size_t(k - 1)] ^ (v[size_t(k - 1)] >> 1);
  std::array<std::array<uint32_t, 256>, 4> t{};
  for (int byte = 0; byte < 4; ++byte)
    for (uint32_t b = 0; b < 256; ++b) {
      uint32_t r = 0;
      for (int j = 0; j < 8; ++j)
        if (b & (1u << j)) r ^= v[size_t(8 * byte + j)];
      t[size_t(byte)][b] = reversed ? reverse_bits_slow(r) : r;
    }
  return t;
}
constexpr auto kDim1 = make_dim1_tables(false);
constexpr auto kDim1Reversed = make_dim1_tables(true);

inline uint32_t byte_table_product(const std::array<std::array<uint32_t, 256>, 4>& t, uint32_t i) {
  return t[0][i & 0xFFu] ^ t[1][(i >> 8) & 0xFFu] ^ t[2][(i >> 16) & 0xFFu] ^ t[3][i >> 24];
}
inline uint32_t sobol_dim1(uint32_t i) { return byte_table_product(kDim1, i); }

// Owen scramble of a 32-bit fixed-point coordinate.
inline uint32_t owen_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(laine_karras_permutation(reverse_bits(x), seed));
}

}  // namespace

uint32_t sample(uint32_t index, int dim) { return dim == 0 ? reverse_bits(index) : sobol_dim1(index); }

uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) { return owen_scramble(x, seed); }

}  // namespace sobol

void Sampler::start_pixel_sample(Vec2i pixel, uint32_t index) {
  if (!(pixel == pixel_)) {
    pixel_ = pixel;
    pixel_hash_ = hash_values(uint64_t(uint32_t(pixel.x)), uint32_t(pixel.y), seed_);
  }
  index_ = index;
  reversed_index_ = sobol::reverse_bits(index);
  dim_ = 0;
  if (type_ == SamplerType::Independent) sample_hash_ = hash_combine(pixel_hash_, index);
}

// Sobol: each request is its own padded sequence. The index is shuffled by a nested uniform
// scramble seeded per (pixel, dimension) so every pixel and dimension walks the sequence in its
// own order, then the point is Owen-scrambled with further hash bits. In bit-reversed space the
// shuffle's output IS the first Sobol coordinate (dimension 0 is the bit reversal of the index),
// which saves two reversals.
float Sampler::next_1d() {
  uint32_t bits;
  if (type_ == SamplerType::Independent) {
    bits = uint32_t(hash_combine(sample_hash_, dim_) >> 32);
  } else {
    uint64_t h = hash_combine(pixel_hash_, dim_);
    uint32_t x = sobol::laine_karras_permutation(reversed_index_, uint32_t(h));
    bits = sobol::owen_scramble(x, uint32_t(h >> 32));
  }
  dim_ += 1;
  return bits_to_unit_float(bits);
}

Vec2 Sampler::next_2d() {
  uint32_t bx, by;
  if (type_ == SamplerType::Independent) {
    uint64_t h = hash_combine(sample_hash_, dim_);
    bx = uint32_t(h >> 32);
    by = uint32_t(h);
  } else {
    uint64_t h = hash_combine(pixel_hash_, dim_);
    uint32_t h2 = uint32_t(mix64(h ^ 0x5851f42d4c957f2dULL));
    // One shared index shuffle keeps the pair a (0,2)-sequence; separate scrambles per axis.
    uint32_t x = sobol::laine_karras_permutation(reversed_index_, uint32_t(h));
    uint32_t shuffled_index = sobol::reverse_bits(x);
    // owen_scramble(v, s) = reverse(permute(reverse(v), s)), with both inner reversals known.
    bx = sobol::reverse_bits(sobol::laine_karras_permutation(shuffled_index, uint32_t(h >> 32)));
    by = sobol::reverse_bits(
        sobol::laine_karras_permutation(sobol::byte_table_product(sobol::kDim1Reversed, shuffled_index), h2));
  }
  dim_ += 2;
  return {bits_to_unit_float(bx), bits_to_unit_float(by)};
}

}  // namespace tessera
