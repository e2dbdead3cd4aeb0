// Agreement of two renders: per-block means with their standard errors (z-tests) for images that
// should converge to the same picture, and bit equality for renders that must be identical.
#pragma once

#include "tessera/render/film.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

namespace tessera::test {

// Mean and squared standard error of the mean of `film` over a block of pixels, per channel.
struct BlockStats {
  double mean[3] = {0, 0, 0}, se2[3] = {0, 0, 0};
};
inline BlockStats block_stats(const Film& film, int x0, int y0, int x1, int y1) {
  BlockStats b;
  double n_pix = double((x1 - x0) * (y1 - y0));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      Rgb m = film.mean({x, y});
      Rgb v = film.sample_variance({x, y});
      double n = double(film.pixel({x, y}).count);
      for (int c = 0; c < 3; ++c) {
        b.mean[c] += m[c] / n_pix;
        b.se2[c] += double(v[c]) / n / (n_pix * n_pix);
      }
    }
  return b;
}

inline bool same_bits(const Film& a, const Film& b) {
  for (int y = a.window().y0; y < a.window().y1; ++y)
    for (int x = a.window().x0; x < a.window().x1; ++x)
      if (std::memcmp(&a.pixel({x, y}), &b.pixel({x, y}), sizeof(PixelSums)) != 0) return false;
  return true;
}

/// z-tests of `a` against `b` (independent renders) over the whole image and blocks of `block`
/// pixels, per channel; |z| < z_max each. Returns the number of tests (for a Bonferroni bound).
inline int expect_same_expectation(const Film& a, const Film& b, int block, double z_max, const std::string& what) {
  const int w = a.width(), h = a.height();
  std::vector<std::array<int, 4>> blocks = {{0, 0, w, h}};
  for (int y = 0; y < h; y += block)
    for (int x = 0; x < w; x += block) blocks.push_back({x, y, std::min(x + block, w), std::min(y + block, h)});
  for (const auto& bl : blocks) {
    const BlockStats sa = block_stats(a, bl[0], bl[1], bl[2], bl[3]), sb = block_stats(b, bl[0], bl[1], bl[2], bl[3]);
    for (int c = 0; c < 3; ++c) {
      const double z = (sa.mean[c] - sb.mean[c]) / std::sqrt(sa.se2[c] + sb.se2[c] + 1e-30);
      EXPECT_LT(std::abs(z), z_max) << what << " block (" << bl[0] << "," << bl[1] << ") channel " << c << ": "
                                    << sa.mean[c] << " vs " << sb.mean[c];
    }
  }
  return int(blocks.size()) * 3;
}

}  // namespace tessera::test
