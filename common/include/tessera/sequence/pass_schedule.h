// How a render is cut: its samples into passes, its window into tiles. Functions of the settings
// alone, so that `tessera render` and every coordinator cut the same work the same way.
#pragma once

#include "tessera/render/film.h"

#include <cstdint>
#include <vector>

namespace tessera {

/// Sample counts of the passes for `spp` samples, a function of spp alone: 1, 2, 4, ... doubling
/// up to 64 per pass, then 64 per pass; the last pass takes the remainder. Early passes are short
/// so a preview (and the farm's first results) arrive quickly; capped so passes stay balanced.
std::vector<uint32_t> pass_schedule(uint32_t spp);

/// Samples per pixel of a guided render's iterations (Müller et al. 2017, a budget in samples):
/// 1, 2, 4, ... doubling without a cap, until what would remain after the next is less than twice
/// it; that one takes the rest, so the last iteration has at least half the samples or so.
/// Every iteration but the last trains the guide the next one samples with.
std::vector<uint32_t> guide_iterations(uint32_t spp);

/// The passes of one iteration of `samples` per pixel: at most 64 each (kMaxPassSamples), the
/// last taking the remainder, so that the farm's units stay small however long an iteration is.
std::vector<uint32_t> iteration_passes(uint32_t samples);
inline constexpr uint32_t kMaxPassSamples = 64;

/// Tiles of `window`, row-major, `tile_size` square (smaller at the right and bottom edges).
std::vector<TileRect> make_tiles(const TileRect& window, int tile_size);

}  // namespace tessera
