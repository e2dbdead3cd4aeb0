// Adaptive sampling in the renderer (RenderSettings::adaptive): it converges to the image of
// uniform sampling (per-block z-tests) on scenes with glossy, delta, glass, media and a sky seen only
// through a pane, with and without guiding, and keeps its mean over many seeds where each pixel's
// samples are heavy-tailed; it spends exactly --spp samples per pixel on average,
// unevenly; a pixel's samples are its first indices in order; and the bits do not depend on
// threads or tiles.
#include "image_agreement.h"
#include "scene_builders.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace tessera {
namespace {

using namespace tessera::test;

RenderSettings adaptive(int spp, uint32_t seed, int threads = 2, int tile_size = 16) {
  RenderSettings s = render_settings(spp, seed, tile_size);
  s.threads = threads;
  s.adaptive = true;
  return s;
}

// Four comparisons, 13 regions (the image and twelve 8x8 blocks), 3 channels: 156 z-tests; |z| < 4
// each has a two-sided probability of 6.3e-5, 0.0099 for all of them (Bonferroni): significance 0.01.
TEST(AdaptiveRender, ConvergesToTheUniformImage) {
  const std::pair<const char*, std::unique_ptr<Scene>> scenes[] = {
      {"mixed", mixed_scene()}, {"fog", fog_scene()}, {"window", window_scene()}};
  for (const auto& [name, scene] : scenes) {
    ASSERT_TRUE(scene) << name;
    RenderStats stats;
    const Film plain = render(*scene, render_settings(512, 31));
    const Film adapted = render(*scene, adaptive(512, 32), {}, &stats);
    EXPECT_EQ(stats.counters.nonfinite, 0u) << name;
    (void)expect_same_expectation(adapted, plain, 8, 4.0, std::string(name) + " adaptive vs uniform");
    if (std::string(name) == "window") {
      RenderSettings both = adaptive(512, 33);
      both.guiding = true;
      both.guiding_settings.emplace().spatial_threshold = 500;  // (a tiny image: let the tree split anyway)
      (void)expect_same_expectation(render(*scene, both), plain, 8, 4.0, "window guided + adaptive vs uniform");
    }
  }
}

// The window room lit only by a small, bright sphere outside the pane: its light arrives only
// on paths that happen to hit the sphere through the glass, so each pixel's samples are heavy-tailed.
std::unique_ptr<Scene> sun_room_scene() {
  return load_edited(kWindowScene,
                     {{R"(<integer name="max_depth" value="8"/>)", R"(<integer name="max_depth" value="3"/>)"},  // (floor -> pane -> sphere)
                      {R"(<emitter type="constant"><rgb name="radiance" value="3,3,3.5"/></emitter>)",
                       R"(<shape type="sphere"><point name="center" value="-4,2,0"/><float name="radius" value="0.1"/>
                            <emitter type="area"><rgb name="radiance" value="3000,3000,3000"/></emitter></shape>)"}},
                     16, 12);
}

// Over many seeds the mean image of adaptive renders matches the uniform one. Each pair shares its
// seed, so the two renders share their first samples and the difference of their means varies far
// less than either (common random numbers); its expectation is still zero for an unbiased rule.
// Counts decided from a pixel's own samples fail this (the image about 30% too dark): pixels that had
// missed the sphere looked converged and kept their dark means. Three z-tests at |z| < 3.2: 0.004.
TEST(AdaptiveRender, AHeavyTailedImageKeepsItsMean) {
  auto scene = sun_room_scene();
  ASSERT_TRUE(scene);
  constexpr int kSeeds = 200;
  std::array<std::vector<double>, 3> differences;
  std::array<double, 3> uniform_mean{};
  for (int i = 0; i < kSeeds; ++i) {
    const BlockStats u = block_stats(render(*scene, render_settings(128, 1 + i, 8)), 0, 0, 16, 12);
    const BlockStats a = block_stats(render(*scene, adaptive(128, 1 + i, 2, 8)), 0, 0, 16, 12);
    for (int c = 0; c < 3; ++c) {
      differences[c].push_back(a.mean[c] - u.mean[c]);
      uniform_mean[c] += u.mean[c] / kSeeds;
    }
  }
  for (int c = 0; c < 3; ++c) {
    double m = 0, v = 0;
    for (double d : differences[c]) m += d / kSeeds;
    for (double d : differences[c]) v += (d - m) * (d - m) / (kSeeds - 1);
    EXPECT_GT(uniform_mean[c], 0.01) << "channel " << c << " is lit";
    EXPECT_LT(std::abs(m) / std::sqrt(v / kSeeds), 3.2) << "channel " << c << ": adaptive - uniform " << m << " of " << uniform_mean[c];
  }
}

TEST(AdaptiveRender, SpendsTheBudgetUnevenly) {
  auto scene = mixed_scene();
  RenderStats stats;
  const Film film = render(*scene, adaptive(64, 4), {}, &stats);
  const uint64_t pixels = uint64_t(film.width()) * uint64_t(film.height());
  EXPECT_EQ(stats.counters.samples, 64 * pixels);
  uint64_t fewest = ~uint64_t(0), most = 0, sum = 0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const uint64_t n = film.pixel({x, y}).count;
      fewest = std::min(fewest, n);
      most = std::max(most, n);
      sum += n;
    }
  EXPECT_EQ(sum, 64 * pixels);
  EXPECT_GE(fewest, 16u);  // (the uniform passes: 1 2 4 8)
  EXPECT_LT(fewest, 64u);
  EXPECT_GT(most, 64u);
}

TEST(AdaptiveRender, APixelTakesItsFirstSampleIndicesInOrder) {
  auto scene = mixed_scene();
  const Film film = render(*scene, adaptive(64, 9));
  for (Vec2i p : {Vec2i{3, 4}, Vec2i{20, 11}, Vec2i{31, 23}}) {
    const PixelSums& px = film.pixel(p);
    FilmTile alone;
    render_tile(*scene, {p.x, p.y, p.x + 1, p.y + 1}, 0, uint32_t(px.count), 9, alone);
    // The same samples, summed in one pass instead of several: equal up to rounding.
    EXPECT_EQ(alone.pixel(p).count, px.count);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(alone.pixel(p).sum[c], px.sum[c], 1e-9 * (1 + std::abs(px.sum[c])));
  }
}

TEST(AdaptiveRender, TheSameBitsForAnyThreadCountAndTileSize) {
  auto scene = mixed_scene();
  const Film a = render(*scene, adaptive(64, 5, /*threads=*/1, /*tile_size=*/8));
  const Film b = render(*scene, adaptive(64, 5, /*threads=*/2, /*tile_size=*/16));
  EXPECT_TRUE(same_bits(a, b));
  RenderSettings off = adaptive(64, 5);
  off.adaptive = false;
  EXPECT_FALSE(same_bits(a, render(*scene, off)));
  EXPECT_TRUE(same_bits(render(*scene, off), render(*scene, render_settings(64, 5))));
}

TEST(AdaptiveRender, StopsAtTheTargetError) {
  auto scene = mixed_scene();
  RenderSettings s = adaptive(4096, 6);
  s.target_error = 0.002;
  RenderStats stats;
  (void)render(*scene, s, {}, &stats);
  EXPECT_LT(stats.spp_done, 4096u);
  EXPECT_LE(stats.noise_estimate, 0.002);
  EXPECT_EQ(stats.counters.samples, uint64_t(stats.spp_done) * 32 * 24);
}

}  // namespace
}  // namespace tessera
