// Path guiding in the renderer (RenderSettings::guiding): a guided render converges to the
// unguided image (per-block z-tests) on a scene of glossy, diffuse and delta surfaces and on one
// with glass and participating media; it is the same bits for any thread count and tile size;
// and with guiding off nothing changes.
#include "image_agreement.h"
#include "scene_builders.h"
#include "tessera/render/renderer.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

using namespace tessera::test;

// Fog around a glass ball filled with a denser medium, a rough metal ball and a diffuse floor,
// lit by a sphere light and a dim sky.
const char* kFogScene = R"(<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="10"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0,1,5" target="0,0.7,0" up="0,1,0"/></transform>
    <medium type="homogeneous" name="medium" id="fog"><float name="sigma_t" value="0.1"/>
      <rgb name="albedo" value="0.8,0.8,0.9"/></medium>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
      <rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="4"/></transform>
    <bsdf type="diffuse"/><ref name="exterior" id="fog"/></shape>
  <shape type="sphere"><point name="center" value="-0.7,0.7,0"/><float name="radius" value="0.6"/>
    <bsdf type="dielectric"/>
    <medium type="homogeneous" name="interior"><float name="sigma_t" value="1.5"/>
      <rgb name="albedo" value="0.9,0.6,0.4"/></medium>
    <ref name="exterior" id="fog"/></shape>
  <shape type="sphere"><point name="center" value="0.8,0.5,0.3"/><float name="radius" value="0.5"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.25"/></bsdf><ref name="exterior" id="fog"/></shape>
  <shape type="sphere"><point name="center" value="0.5,2.6,1"/><float name="radius" value="0.6"/>
    <emitter type="area"><rgb name="radiance" value="8,7,6"/></emitter><ref name="exterior" id="fog"/></shape>
  <emitter type="constant"><rgb name="radiance" value="0.2,0.25,0.3"/></emitter>
</scene>)";

// A closed room lit only by a sky seen through a window pane, which next-event estimation
// cannot see through: every light path leaves through the pane by sampling (the case guiding is for).
const char* kWindowScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="8"/></integrator>
  <sensor type="perspective"><float name="fov" value="70"/>
    <transform name="to_world"><lookat origin="0,0,0.9" target="0,-0.2,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
      <rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="wall"><rgb name="reflectance" value="0.7,0.6,0.5"/></bsdf>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><translate y="-1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><translate y="1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><translate z="-1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="180"/><translate z="1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="-90"/><translate x="1"/></transform>
    <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate y="1" angle="90"/><translate x="-1"/></transform>
    <bsdf type="thindielectric"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="0.25"/><rotate y="1" angle="90"/>
    <translate x="-1" y="0.75"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="0.25"/><rotate y="1" angle="90"/>
    <translate x="-1" y="-0.75"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.25" y="0.5"/><rotate y="1" angle="90"/>
    <translate x="-1" z="0.75"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.25" y="0.5"/><rotate y="1" angle="90"/>
    <translate x="-1" z="-0.75"/></transform><ref id="wall"/></shape>
  <emitter type="constant"><rgb name="radiance" value="3,3,3.5"/></emitter>
</scene>)";

std::unique_ptr<Scene> window_scene() {
  LoadResult r = load_scene(parse_scene_string(kWindowScene, "window_scene.xml"), LoadOptions{});
  return std::move(r.scene);
}

std::unique_ptr<Scene> fog_scene() {
  LoadResult r = load_scene(parse_scene_string(kFogScene, "fog_scene.xml"), LoadOptions{});
  return std::move(r.scene);
}

RenderSettings guided(int spp, uint32_t seed, int threads = 2, int tile_size = 16) {
  RenderSettings s = render_settings(spp, seed, tile_size);
  s.threads = threads;
  s.guiding = true;
  s.guiding_settings.spatial_threshold = 500;  // (a tiny image: let the tree split anyway)
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
  s.guiding_settings.discard_training = false;
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
