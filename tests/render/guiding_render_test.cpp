// Path guiding in the renderer (RenderSettings::guiding): a guided render converges to the
// unguided image (per-block z-tests) on a scene of glossy, diffuse and delta surfaces and on one
// with glass and participating media; it is the same bits for any thread count and tile size;
// and with guiding off nothing changes.
#include "image_agreement.h"
#include "scene_builders.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

using namespace tessera::test;

RenderSettings guided(int spp, uint32_t seed, int threads = 2, int tile_size = 16) {
  RenderSettings s = render_settings(spp, seed, tile_size);
  s.threads = threads;
  s.guiding = true;
  s.guiding_settings.emplace().spatial_threshold = 500;  // (a tiny image: let the tree split anyway)
  return s;
}

// Three scenes, 13 regions (the image and twelve 8x8 blocks), 3 channels: 117 z-tests; |z| < 4
// each has a two-sided probability of 6.3e-5, 0.0074 for all of them (Bonferroni): significance 0.01.
TEST(GuidedRender, ConvergesToTheUnguidedImage) {
  const std::pair<const char*, std::unique_ptr<Scene>> scenes[] = {
      {"mixed", mixed_scene()}, {"fog", fog_scene()}, {"window", window_scene()}};
  for (const auto& [name, scene] : scenes) {
    ASSERT_TRUE(scene) << name;
    RenderStats plain_stats, guided_stats;
    const Film plain = render(*scene, render_settings(512, 21), {}, &plain_stats);
    const Film with_guide = render(*scene, guided(512, 22), {}, &guided_stats);
    EXPECT_EQ(guided_stats.counters.nonfinite, 0u) << name;
    (void)expect_same_expectation(with_guide, plain, 8, 4.0, std::string(name) + " guided vs unguided");
    EXPECT_GT(block_stats(plain, 0, 0, plain.width(), plain.height()).mean[1], 0.05) << name << " is lit";
  }
}

TEST(GuidedRender, TheSameBitsForAnyThreadCountAndTileSize) {
  auto scene = mixed_scene();
  const Film a = render(*scene, guided(64, 5, /*threads=*/1, /*tile_size=*/8));
  const Film b = render(*scene, guided(64, 5, /*threads=*/2, /*tile_size=*/16));
  EXPECT_TRUE(same_bits(a, b));
  // Guiding changes the samples (after the training passes), and off is the unguided render.
  RenderSettings off = guided(64, 5);
  off.guiding = false;
  EXPECT_FALSE(same_bits(a, render(*scene, off)));
  EXPECT_TRUE(same_bits(render(*scene, off), render(*scene, render_settings(64, 5))));
}

TEST(GuidedRender, TheImageIsMadeOfThePassesAfterTraining) {
  auto scene = mixed_scene();
  // 16 spp: passes 1 2 4 8 | 1; the first three train.
  RenderSettings s = guided(16, 3);
  RenderStats stats;
  const Film discarded = render(*scene, s, {}, &stats);
  EXPECT_EQ(discarded.pixel({5, 5}).count, 9u);
  EXPECT_EQ(stats.counters.samples, 16u * uint64_t(discarded.width() * discarded.height()));
  s.guiding_settings->discard_training = false;
  EXPECT_EQ(render(*scene, s).pixel({5, 5}).count, 16u);
}

TEST(GuidedRender, OnlyTheFirstHalfOfTheSamplesTrains) {
  const std::vector<uint32_t> passes = pass_schedule(64);  // 1 2 4 8 16 32 1
  std::vector<bool> trains;
  for (size_t p = 0; p < passes.size(); ++p) trains.push_back(guiding_trains_pass(passes, p, 64));
  EXPECT_EQ(trains, (std::vector<bool>{true, true, true, true, true, false, false}));  // ends 1 3 7 15 31 | 63 64
  EXPECT_FALSE(guiding_trains_pass(pass_schedule(1), 0, 1));
  EXPECT_FALSE(guiding_trains_pass(passes, passes.size(), 64));
}

}  // namespace
}  // namespace tessera
