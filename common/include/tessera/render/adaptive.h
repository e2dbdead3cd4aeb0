// Adaptive sampling: after the first passes, each pass's samples go to the pixels whose error the
// film's own variance estimate says is largest, instead of the same number to every pixel.
//
// A pass keeps its budget (its samples per pixel times the pixels), so --spp stays the total.
// How the budget is split is a function of the film of the completed passes alone: every tiling,
// thread count or farm decides the same counts, and a pixel's samples keep their consecutive
// indices, so each value still depends only on (pixel, sample index, seed).
//
// The split minimises the expected relMSE after the pass, the form of noise_estimate.h. A pixel
// with per-sample relative variance v = s^2 / (mean^2 + 0.01) and N samples contributes v / N;
// over a fixed total, sum v_i / T_i is smallest with T_i proportional to sqrt(v_i) (Neyman
// allocation). Samples already taken cannot be returned, so the pass fills up the pixels furthest
// below their share (water filling); a pixel already above it takes none: it has converged
// relative to the rest.
//
// A pixel's v is the mean over its four edge neighbours, not its own. Deciding a pixel's count from
// its own samples biases it: a pixel whose samples missed the rare bright paths looks converged,
// takes fewer samples and keeps its dark mean, while one that caught a firefly takes more and
// dilutes it. On kitchenette (sun through a window) that made the image 15% too dark at 256 spp.
// The pixels are coloured as a checkerboard, whose edge neighbours are the other colour, and each
// colour shares out its own half of the budget: a pixel's count is then a function of the other
// colour's samples alone, which are independent of its own, so its mean stays unbiased for the
// count chosen. (Were the budget shared by all, a pixel that caught a firefly would raise its
// neighbours' weights, lowering the common level and with it its own count: a few percent too
// bright on a 16 x 12 image.)
#pragma once

#include "tessera/render/film.h"

#include <cstdint>
#include <vector>

namespace tessera {

struct AdaptiveSettings {
  /// A pass is adaptive only once every pixel of the film holds this many samples (fewer give no
  /// usable variance) and the pass begins at uniform_fraction of the budget or later.
  uint32_t min_samples = 8;
  double uniform_fraction = 0.25;
  /// A pixel takes at most this many times the pass's samples per pixel in one pass.
  uint32_t max_factor = 4;
};

/// One pass's samples of each pixel of `rect`: pixel p takes sample indices
/// [first[i], first[i] + count[i]), i its row-major index in rect.
struct PassSamples {
  TileRect rect;
  std::vector<uint32_t> first, count;

  /// Every pixel of `rect` takes [begin, end).
  static PassSamples uniform(const TileRect& rect, uint32_t begin, uint32_t end);
  size_t index(Vec2i p) const { return size_t(p.y - rect.y0) * size_t(rect.width()) + size_t(p.x - rect.x0); }
  bool operator==(const PassSamples&) const = default;
};

/// Whether pass `pass` (beginning at sample `begin` of `spp`) may be adaptive, given the fewest
/// samples any pixel of the film holds.
bool adaptive_pass(uint32_t begin, uint32_t spp, uint64_t fewest_film_samples, const AdaptiveSettings& s);

/// The fewest samples a pixel of the film holds.
uint64_t fewest_samples(const Film& film);

/// Splits a pass of `pass_spp` samples per pixel among the film's pixels (row-major over its
/// window) as described above, each at most settings.max_factor * pass_spp. The counts add up to
/// pass_spp times the pixels exactly.
std::vector<uint32_t> allocate_samples(const Film& film, uint32_t pass_spp, const AdaptiveSettings& settings);

/// The samples of a pass of `pass_spp` per pixel that begins at sample `begin` of `spp`, over the
/// film's window: allocated when `adaptive` is given and adaptive_pass() allows, else the same for
/// every pixel. `taken` holds each pixel's samples so far (its next index), row-major.
PassSamples plan_pass(const Film& film, const std::vector<uint32_t>& taken, uint32_t begin, uint32_t pass_spp,
                      uint32_t spp, const AdaptiveSettings* adaptive);

}  // namespace tessera
