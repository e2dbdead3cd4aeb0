// Agreement of estimators whose noise a pixel's sample variance does not show (a light tracer's
// splats): K independent renders (seeds) of each, their block means' spread giving the standard
// error with K - 1 degrees of freedom.
#pragma once

#include "scene_builders.h"
#include "tessera/image/image.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace tessera::test {

// Per block (and the whole image) and channel: the mean over K renders and its squared standard
// error from their spread.
struct Estimate {
  std::vector<std::array<int, 4>> blocks;
  std::vector<std::array<double, 3>> mean, se2;
};

inline std::vector<std::array<int, 4>> blocks_of(int w, int h, int block) {
  std::vector<std::array<int, 4>> b = {{0, 0, w, h}};
  for (int y = 0; y < h; y += block)
    for (int x = 0; x < w; x += block) b.push_back({x, y, std::min(x + block, w), std::min(y + block, h)});
  return b;
}

inline std::array<double, 3> block_mean(const Image& img, const std::array<int, 4>& b) {
  std::array<double, 3> m{};
  const double n = double((b[2] - b[0]) * (b[3] - b[1]));
  for (int y = b[1]; y < b[3]; ++y)
    for (int x = b[0]; x < b[2]; ++x)
      for (int c = 0; c < 3; ++c) m[size_t(c)] += double(img.at(x, y, c)) / n;
  return m;
}

/// K images `image_of(seed)`, seeds seed0, seed0 + 1, ...
inline Estimate estimate_of(const std::function<Image(uint32_t)>& image_of, int renders, int block, uint32_t seed0) {
  Estimate e;
  std::vector<std::vector<std::array<double, 3>>> per;
  for (int k = 0; k < renders; ++k) {
    const Image img = image_of(seed0 + uint32_t(k));
    if (k == 0) {
      e.blocks = blocks_of(img.width(), img.height(), block);
      per.resize(e.blocks.size());
    }
    for (size_t b = 0; b < e.blocks.size(); ++b) per[b].push_back(block_mean(img, e.blocks[b]));
  }
  for (const auto& values : per) {
    std::array<double, 3> m{}, v{};
    for (const auto& x : values)
      for (int c = 0; c < 3; ++c) m[size_t(c)] += x[size_t(c)] / double(renders);
    for (const auto& x : values)
      for (int c = 0; c < 3; ++c) v[size_t(c)] += std::pow(x[size_t(c)] - m[size_t(c)], 2) / double(renders - 1);
    for (double& x : v) x /= double(renders);
    e.mean.push_back(m);
    e.se2.push_back(v);
  }
  return e;
}

// |t| < t_max for every block and channel. With 16 renders a side, t has about 15 degrees of
// freedom or more: P(|t| > 6) < 3e-5 each, below 0.01 over a few hundred tests. The image must
// be lit (green mean of the whole above `lit`), or the agreement says nothing.
inline void expect_agree(const Estimate& a, const Estimate& b, double t_max, const std::string& what, double lit = 0.02) {
  ASSERT_EQ(a.blocks.size(), b.blocks.size());
  for (size_t i = 0; i < a.blocks.size(); ++i)
    for (size_t c = 0; c < 3; ++c) {
      const double t = (a.mean[i][c] - b.mean[i][c]) / std::sqrt(a.se2[i][c] + b.se2[i][c] + 1e-30);
      EXPECT_LT(std::abs(t), t_max) << what << " block (" << a.blocks[i][0] << "," << a.blocks[i][1] << ") channel "
                                    << c << ": " << a.mean[i][c] << " vs " << b.mean[i][c];
    }
  EXPECT_GT(a.mean[0][1], lit) << what << ": the image is lit";
}

/// K renders of `scene` at `spp` (render_settings of scene_builders.h).
inline Estimate estimate(const Scene& scene, int spp, int renders, int block, uint32_t seed0) {
  return estimate_of([&](uint32_t seed) { return render(scene, render_settings(spp, seed)).to_image(); }, renders, block,
                     seed0);
}

}  // namespace tessera::test
