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

/// Whether pass `pass` of `passes` (for `spp` samples) trains the guide of a guided render: those
/// that end within the first half of the samples (none with fewer than 2 samples per pixel).
bool guiding_trains_pass(const std::vector<uint32_t>& passes, size_t pass, uint32_t spp);

/// Tiles of `window`, row-major, `tile_size` square (smaller at the right and bottom edges).
std::vector<TileRect> make_tiles(const TileRect& window, int tile_size);

}  // namespace tessera
