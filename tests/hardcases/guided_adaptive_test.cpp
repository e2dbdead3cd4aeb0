// Hard cases for path guiding and adaptive sampling together: light that arrives only at the last
// bounce a path may take, a scene lit only by its environment, training iterations that record
// nothing, and a memory cap so small the spatial tree cannot split. Every image is finite and agrees
// with the plain render per 8x8 block within 4 standard errors.
#include "hardcase_support.h"
#include "render/image_agreement.h"
#include "render/scene_builders.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace tessera {
namespace {

using namespace tessera::test;

RenderSettings guided_adaptive(int spp, uint32_t seed) {
  RenderSettings s = hard_settings(spp, seed);
  s.guiding = true;
  s.adaptive = true;
  s.guiding_settings.emplace().spatial_threshold = 500;  // (tiny images: let the tree split anyway)
  return s;
}

// Compares a guided + adaptive render with a plain one. Four cases here, 13 regions, 3 channels:
// 156 z-tests at |z| < 4, significance 0.01 (Bonferroni).
void expect_agrees(const Scene& scene, const RenderSettings& settings, const std::string& what) {
  const Film plain = render_checked(scene, hard_settings(512, 41), what + " (plain)");
  const Film both = render_checked(scene, settings, what);
  (void)expect_same_expectation(both, plain, 8, 4.0, what);
}

TEST(HardGuidedAdaptive, LightOnlyAtTheLastBounce) {
  // The room lit through a pane: with max_depth 3 the sky counts only on camera -> wall -> pane ->
  // sky, so a path's radiance arrives at its last vertex or not at all.
  auto scene = load_edited(kWindowScene, {{R"(<integer name="max_depth" value="8"/>)", R"(<integer name="max_depth" value="3"/>)"}});
  ASSERT_TRUE(scene);
  expect_agrees(*scene, guided_adaptive(512, 42), "last bounce");
}

TEST(HardGuidedAdaptive, LitOnlyByTheEnvironment) {
  // The mixed scene's objects (diffuse, plastic, smooth and rough metal) under its sky alone.
  auto scene = load_edited(kMixedScene, {{R"(<emitter type="area"><rgb name="radiance" value="12,10,8"/></emitter>)", ""},
                                         {R"(<emitter type="area"><rgb name="radiance" value="4,4,5"/></emitter>)", ""},
                                         {R"(<emitter type="point"><point name="position" x="-1.2" y="1.8" z="1.5"/><rgb name="intensity" value="3"/></emitter>)", ""}});
  ASSERT_TRUE(scene);
  ASSERT_EQ(scene->lights.size(), 1u);
  expect_agrees(*scene, guided_adaptive(512, 43), "environment only");
}

TEST(HardGuidedAdaptive, TrainingThatRecordsNothing) {
  // No light at all: every training record is zero, and the image must stay exactly black.
  auto dark = load_edited(kWindowScene, {{R"(<emitter type="constant"><rgb name="radiance" value="3,3,3.5"/></emitter>)", ""}});
  ASSERT_TRUE(dark);
  RenderStats stats;
  const Film film = render_checked(*dark, guided_adaptive(64, 44), "no light", &stats);
  EXPECT_EQ(black_fraction(film.to_image()), 1.0);
  EXPECT_EQ(stats.counters.samples, 64u * 32 * 24);
  // The camera sees only the sky: no path has a vertex to record.
  auto open = load_edited(R"(<scene version="3.0.0"><sensor type="perspective"><film type="hdrfilm">
    <integer name="width" value="16"/><integer name="height" value="12"/></film><sampler type="independent"/></sensor>
    <emitter type="constant"><rgb name="radiance" value="0.5,1,2"/></emitter></scene>)", {});
  ASSERT_TRUE(open);
  const auto sky = channel_means(render_checked(*open, guided_adaptive(64, 45), "sky only").to_image());
  EXPECT_FLOAT_EQ(float(sky[0]), 0.5f);
  EXPECT_FLOAT_EQ(float(sky[1]), 1.f);
  EXPECT_FLOAT_EQ(float(sky[2]), 2.f);
}

TEST(HardGuidedAdaptive, ATreeThatCannotSplit) {
  auto scene = mixed_scene();
  ASSERT_TRUE(scene);
  RenderSettings s = guided_adaptive(512, 46);
  s.guiding_settings->max_bytes = 1;  // below a single leaf: the root stays the only leaf
  expect_agrees(*scene, s, "one leaf");
}

}  // namespace
}  // namespace tessera
