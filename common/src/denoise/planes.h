// Planar float images for the denoiser's filters: one contiguous row-major array per channel, so
// the inner loops run over consecutive pixels of one channel (and vectorise).
#pragma once

#include "tessera/image/image.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera::denoise_detail {

struct Planes {
  int width = 0, height = 0;
  std::vector<std::vector<float>> c;  // c[channel][y * width + x]

  Planes() = default;
  Planes(int w, int h, int channels) : width(w), height(h), c(size_t(channels), std::vector<float>(size_t(w) * size_t(h))) {}
  int channels() const { return int(c.size()); }
  size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
  float at(int ch, int x, int y) const { return c[size_t(ch)][index(x, y)]; }
};

inline int clamp_coord(int v, int n) { return std::min(std::max(v, 0), n - 1); }

/// The channels of `img` as planes; a value that is not finite (a damaged file) becomes 0 rather
/// than spreading through every window that holds it.
inline Planes to_planes(const Image& img) {
  Planes p(img.width(), img.height(), img.channels());
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      for (int ch = 0; ch < img.channels(); ++ch) {
        const float v = img.at(x, y, ch);
        p.c[size_t(ch)][p.index(x, y)] = std::isfinite(v) ? v : 0.f;
      }
  return p;
}

}  // namespace tessera::denoise_detail
