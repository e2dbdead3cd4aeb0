// Path guiding in the renderer (RenderSettings::guiding): a guided render converges to the
// unguided image (per-block z-tests) on a scene of glossy, diffuse and delta surfaces and on one
// with glass and participating media; it is the same bits for any thread count and tile size;
// and with guiding off nothing changes.
#include "image_agreement.h"
#include "scene_builders.h"
#include "test_support.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "tessera/sequence/guide_training.h"
#include "tessera/sequence/pass_schedule.h"
#include "tessera/sequence/path_program.h"
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

// scenes/window-pane (a room lit by the sky through a pane of glass) at 32x24.
std::unique_ptr<Scene> window_pane_scene() {
  LoadOptions o;
  o.width = 32;
  o.height = 24;
  return std::move(load_scene(parse_scene_file(source_dir() + "/scenes/window-pane/scene.xml"), o).scene);
}

// Four scenes, 13 regions each (the image and twelve 8x8 blocks), 3 channels: 156 z-tests; |z| < 4
// each has a two-sided probability of 6.3e-5, 0.0099 for all of them (Bonferroni): significance 0.01.
// The image combines the last four iterations by inverse variance (the default), whose weights
// come from the images themselves: its bias must be below what these tests resolve.
TEST(GuidedRender, ConvergesToTheUnguidedImage) {
  const std::pair<const char*, std::unique_ptr<Scene>> scenes[] = {
      {"mixed", mixed_scene()}, {"fog", fog_scene()}, {"window", window_scene()}, {"window-pane", window_pane_scene()}};
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

TEST(GuidedRender, DiscardKeepsTheLastIterationOnly) {
  auto scene = mixed_scene();
  // 16 spp: iterations of 1, 2, 4 and 9 samples; the last is the image.
  RenderSettings s = guided(16, 3);
  s.guiding_settings->combination = GuideCombination::Discard;
  RenderStats stats;
  const Film discarded = render(*scene, s, {}, &stats);
  EXPECT_EQ(discarded.pixel({5, 5}).count, 9u);
  EXPECT_EQ(stats.counters.samples, 16u * uint64_t(discarded.width() * discarded.height()));
  // Combined: the four iterations' samples, over the largest power of two within them.
  s.guiding_settings->combination = GuideCombination::InverseVariance;
  EXPECT_EQ(render(*scene, s).pixel({5, 5}).count, 16u);
}

TEST(GuidedRender, IterationsDoubleWithoutACapAndTheLastTakesTheRest) {
  EXPECT_EQ(guide_iterations(1), (std::vector<uint32_t>{1}));
  EXPECT_EQ(guide_iterations(2), (std::vector<uint32_t>{2}));
  EXPECT_EQ(guide_iterations(3), (std::vector<uint32_t>{1, 2}));
  EXPECT_EQ(guide_iterations(4), (std::vector<uint32_t>{1, 3}));
  EXPECT_EQ(guide_iterations(16), (std::vector<uint32_t>{1, 2, 4, 9}));
  EXPECT_EQ(guide_iterations(128), (std::vector<uint32_t>{1, 2, 4, 8, 16, 32, 65}));
  EXPECT_EQ(guide_iterations(1024), (std::vector<uint32_t>{1, 2, 4, 8, 16, 32, 64, 128, 256, 513}));
  EXPECT_EQ(iteration_passes(513), (std::vector<uint32_t>{64, 64, 64, 64, 64, 64, 64, 64, 1}));
  EXPECT_EQ(iteration_passes(32), (std::vector<uint32_t>{32}));
}

TEST(GuidedRender, AnIterationIsARunOfPassesWithOneGuide) {
  PathProgramOptions o;
  o.spp = 256;  // iterations 1 2 4 8 16 32 64 129: passes 1 2 4 8 16 32 64 64 64 1
  o.guide = GuidePlan{Bounds3(Vec3(0.f), Vec3(1.f)), GuidingSettings{}};
  const PassProgram p = path_program(o);
  ASSERT_EQ(p.passes.size(), 10u);
  EXPECT_EQ(p.films, 4);
  EXPECT_EQ(p.combine, FilmCombine::InverseVariance);
  const int uses[] = {0, 1, 2, 3, 4, 5, 6, 7, 7, 7};
  const int film[] = {kNoFilm, kNoFilm, kNoFilm, kNoFilm, 0, 1, 2, 3, 3, 3};
  for (size_t k = 0; k < p.passes.size(); ++k) {
    const PassSpec& pass = p.passes[k];
    EXPECT_EQ(pass.uses, std::optional<uint32_t>(uses[k])) << k;
    EXPECT_EQ(pass.feeds, uses[k] < 7 ? std::optional<uint32_t>(uses[k] + 1) : std::nullopt) << k;
    EXPECT_EQ(pass.film, film[k]) << k;
    EXPECT_EQ(pass.barrier, k > 0 && k < 8) << k;  // (a new guide: the first pass of each iteration)
  }
  o.guide->settings.combination = GuideCombination::Discard;
  const PassProgram d = path_program(o);
  EXPECT_EQ(d.films, 1);
  EXPECT_EQ(d.passes[6].film, kNoFilm);
  EXPECT_EQ(d.passes[7].film, 0);
}

// Leaves split once their samples in an iteration of spp_k samples a pixel exceed c·sqrt(spp_k / 4):
// the sequencer passes each iteration's samples to the tree.
// Where the guide cannot pay (cornell-box: next-event estimation finds its one light) its
// prediction is below the least gain and the render steps aside; through a window pane the light
// is found only by the guide, and it keeps guiding. Both at 96x72 and 128 spp, deciding at the
// first iteration of 2^17 paths (32 spp).
TEST(GuidedRender, StepsAsideWhereTheGuidePredictsLittleAndNotWhereItPredictsMuch) {
  const std::string cornell = shared_path("scenes/cornell-box/scene.xml");
  TESSERA_REQUIRE_FILE(cornell);
  LoadOptions o;
  o.width = 96;
  o.height = 72;
  const std::unique_ptr<Scene> direct = std::move(load_scene(parse_scene_file(cornell), o).scene);
  const std::unique_ptr<Scene> window =
      std::move(load_scene(parse_scene_file(source_dir() + "/scenes/window-pane/scene.xml"), o).scene);
  RenderSettings s = render_settings(128, 3);
  s.guiding = true;
  s.guiding_settings.emplace().gain_paths = uint64_t(1) << 17;
  RenderStats direct_stats, window_stats;
  (void)render(*direct, s, {}, &direct_stats);
  (void)render(*window, s, {}, &window_stats);
  EXPECT_TRUE(direct_stats.guide_stepped_aside) << "predicted " << direct_stats.guide_gain;
  EXPECT_GT(direct_stats.guide_gain, 0.f);
  EXPECT_LT(direct_stats.guide_gain, 1.3f);
  EXPECT_EQ(direct_stats.guide_leaves, 1u);
  EXPECT_FALSE(window_stats.guide_stepped_aside) << "predicted " << window_stats.guide_gain;
  EXPECT_GT(window_stats.guide_gain, 1.3f);
}

TEST(GuidedRender, TheSplitThresholdFollowsTheIterationsSamples) {
  PathProgramOptions o;
  o.spp = 16;  // iterations 1 2 4 9
  GuidingSettings g;
  g.spatial_threshold = 400;  // iteration 0 (1 spp): 200; iteration 1 (2 spp): 282.8
  o.guide = GuidePlan{Bounds3(Vec3(0.f), Vec3(1.f)), g};
  PassSequencer seq = path_sequencer(o, SequenceFrame{TileRect{0, 0, 4, 4}, 4, 4, 4, false});
  auto* training = dynamic_cast<GuideTraining*>(seq.builder());
  ASSERT_NE(training, nullptr);
  ASSERT_NE(training->latest(), nullptr);  // (iteration 0: one leaf, made with the sequencer)
  for (int i = 0; i < 1000; ++i) training->recorder().record(0, Vec3(0.f, 0.f, 1.f), 1.f, 0.5f);
  // (A split leaf's halves each keep half its samples: 1000 > 200, 2 x 500 > 200, 4 x 250 > 200,
  // 8 x 125.)
  (void)training->build(1);
  EXPECT_EQ(training->tree_leaves(), 8u);
  const uint32_t leaf = training->latest()->leaf_of(Vec3(0.f));
  for (int i = 0; i < 1000; ++i) training->recorder().record(leaf, Vec3(0.f, 0.f, 1.f), 1.f, 0.5f);
  (void)training->build(2);  // 1000 > 282.8, 2 x 500 > 282.8, 4 x 250: three more
  EXPECT_EQ(training->tree_leaves(), 11u);
}

}  // namespace
}  // namespace tessera
