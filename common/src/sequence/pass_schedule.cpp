#include "tessera/sequence/pass_schedule.h"

#include "tessera/core/check.h"

#include <algorithm>

namespace tessera {

std::vector<uint32_t> pass_schedule(uint32_t spp) {
  std::vector<uint32_t> passes;
  uint32_t done = 0, next = 1;
  while (done < spp) {
    uint32_t n = std::min(next, spp - done);
    passes.push_back(n);
    done += n;
    next = std::min(next * 2, kMaxPassSamples);
  }
  return passes;
}

std::vector<uint32_t> guide_iterations(uint32_t spp) {
  std::vector<uint32_t> iterations;
  uint64_t next = 1;
  for (uint32_t remaining = spp; remaining > 0; next *= 2) {
    uint32_t n = uint32_t(std::min<uint64_t>(next, remaining));
    // (As Müller's: an iteration that could not be followed by one twice its size takes the rest.)
    if (uint64_t(remaining - n) < 2 * uint64_t(n)) n = remaining;
    iterations.push_back(n);
    remaining -= n;
  }
  return iterations;
}

std::vector<uint32_t> iteration_passes(uint32_t samples) {
  std::vector<uint32_t> passes(samples / kMaxPassSamples, kMaxPassSamples);
  if (samples % kMaxPassSamples) passes.push_back(samples % kMaxPassSamples);
  return passes;
}

std::vector<TileRect> make_tiles(const TileRect& window, int tile_size) {
  TESSERA_CHECK(tile_size > 0);
  std::vector<TileRect> tiles;
  for (int y = window.y0; y < window.y1; y += tile_size)
    for (int x = window.x0; x < window.x1; x += tile_size)
      tiles.push_back({x, y, std::min(x + tile_size, window.x1), std::min(y + tile_size, window.y1)});
  return tiles;
}

}  // namespace tessera
