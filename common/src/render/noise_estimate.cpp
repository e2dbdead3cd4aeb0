#include "tessera/render/noise_estimate.h"

#include <algorithm>
#include <limits>

namespace tessera {

NoiseEstimate estimate_noise(const Film& film, double clamp) {
  NoiseEstimate e;
  const TileRect& w = film.window();
  double sum = 0;  // pixel order is fixed, so the estimate is deterministic for a given film
  for (int y = w.y0; y < w.y1; ++y)
    for (int x = w.x0; x < w.x1; ++x) {
      const PixelSums& p = film.pixel({x, y});
      if (p.count < 2) return {std::numeric_limits<double>::infinity(), 0};
      const Rgb mean = film.mean({x, y}), var = film.sample_variance({x, y});
      for (int c = 0; c < 3; ++c)
        sum += std::min(clamp, (double(var[c]) / double(p.count)) / (double(mean[c]) * mean[c] + 0.01));
      ++e.pixels;
    }
  e.rel_mse = e.pixels ? sum / double(3 * e.pixels) : std::numeric_limits<double>::infinity();
  return e;
}

}  // namespace tessera
