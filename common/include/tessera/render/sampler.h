// Stateless-by-construction sample generator.
//
// A sample value depends only on (pixel, sample index, dimension, seed): the sampler keeps nothing
// but a dimension counter, so an image is bit-identical for any thread count, tile size or tile
// order, and a tile rendered on another machine reproduces the same bits.
//
// Dimension allocation (the counter advances by 1 per next_1d() and by 2 per next_2d()):
//   camera:      film position 2D (dims 0-1), lens 2D (dims 2-3)
//   per bounce:  light pick 1D, light position 2D, BSDF lobe 1D, BSDF direction 2D, Russian
//                roulette 1D  (7 dimensions per bounce, always consumed in this order so that a
//                given dimension means the same thing in every path)
//   volpath:     on a scene with media, each ray segment first takes a medium 2D (channel,
//                distance); a scattering point in a medium then takes the same 7 dimensions as a
//                surface bounce (the lobe dimension unused, the phase direction in the BSDF's 2D)
// time:        only when the shutter is open for a non-zero interval (motion blur), the camera ray's
//              time from dimension kTimeDimension, read with sample_1d_at() so the counter, and
//              thus every dimension above, is the same as without motion blur
// bdpt/ptracer: the camera subpath as above (the light-pick and light-position dimensions feed
//              next-event estimation); the light subpath from kLightDimension: light pick 1D,
//              emission position 2D, emission direction 2D, then per bounce BSDF lobe 1D, BSDF
//              direction 2D, Russian roulette 1D, lens 2D (the camera connection)
// The direct integrator uses, per hit, (1D + 2D) per emitter sample then (1D + 2D) per BSDF sample.
//
// Types:
//   Sobol        Owen-scrambled, shuffled Sobol with padding (Burley 2020, "Practical Hash-based
//                Owen Scrambling"): each 1D/2D request is its own padded (0,2)-sequence whose index
//                is shuffled by a nested uniform scramble seeded with hash(pixel, dim, seed), and
//                whose coordinates are then Owen-scrambled with further hashes.
//   Independent  hash(pixel, index, dim, seed) -> uniform.
#pragma once

#include "tessera/core/vec.h"
#include "tessera/render/scene.h"

#include <cstdint>

namespace tessera {

class Sampler {
 public:
  Sampler(SamplerType type, uint32_t seed) : type_(type), seed_(seed) {}

  /// Positions the sampler at sample `index` of `pixel` (full-film raster pixel), dimension 0.
  void start_pixel_sample(Vec2i pixel, uint32_t index);
  /// Uniform in [0, 1).
  float next_1d();
  /// Uniform in [0, 1)^2.
  Vec2 next_2d();

  /// The value next_1d() would return at dimension `dim`, leaving the counter where it is: for
  /// dedicated dimensions outside the sequential layout (kTimeDimension).
  float sample_1d_at(uint32_t dim) {
    const uint32_t saved = dim_;
    dim_ = dim;
    const float u = next_1d();
    dim_ = saved;
    return u;
  }
  /// Far above any sequential dimension a path reaches.
  static constexpr uint32_t kTimeDimension = 0xFFFFFF00u;

  uint32_t dimension() const { return dim_; }
  /// Moves the counter to `dim`: a block of dimensions of its own (kLightDimension).
  void set_dimension(uint32_t dim) { dim_ = dim; }
  /// Where light subpaths of bidirectional methods start drawing (bdpt.h), far from the camera
  /// path's dimensions, so a pixel sample's light subpath is the same whichever unit traces it.
  static constexpr uint32_t kLightDimension = 0x40000000u;
  SamplerType type() const { return type_; }
  uint32_t seed() const { return seed_; }

 private:
  SamplerType type_;
  uint32_t seed_;
  Vec2i pixel_{-1, -1};
  uint64_t pixel_hash_ = 0;   // hash(pixel, seed), cached across the samples of a pixel
  uint64_t sample_hash_ = 0;  // hash(pixel, index, seed), for the independent sampler
  uint32_t index_ = 0;
  uint32_t reversed_index_ = 0;  // index_ with its bits reversed, where the Sobol shuffle starts
  uint32_t dim_ = 0;
};

namespace sobol {
/// Bits of the first two Sobol dimensions (dim 0: van der Corput; dim 1: the Pascal matrix).
uint32_t sample(uint32_t index, int dim);
/// Burley's nested uniform scramble (an Owen scramble of a 32-bit fixed-point value).
uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed);
}  // namespace sobol

}  // namespace tessera
