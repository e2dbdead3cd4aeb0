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
    next = std::min(next * 2, 64u);
  }
  return passes;
}

bool guiding_trains_pass(const std::vector<uint32_t>& passes, size_t pass, uint32_t spp) {
  uint32_t end = 0;
  for (size_t p = 0; p <= pass && p < passes.size(); ++p) end += passes[p];
  return pass < passes.size() && end <= spp / 2;
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
