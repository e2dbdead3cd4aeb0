// Each strategy of bidirectional path tracing alone (IntegratorSettings::only_s/only_t, weight 1):
// strategy (s, t) renders exactly the light of paths of s + t - 1 segments, which is the path
// tracer at that max depth minus the path tracer at one less (the same seed: both share the
// shorter paths bit for bit). A strategy that counted a path twice, missed one, or carried the
// wrong throughput, density or importance shows here on its own, where under MIS it would be
// diluted by the others.
#include "independent_renders.h"
#include "tessera/render/bdpt.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace tessera {
namespace {

using namespace tessera::test;

// A closed diffuse box (every camera ray hits something) with a wide ceiling light in view and two
// blocks. A box filter: light tracing alone reaches only points on the film, where a wider
// filter's camera samples of the edge pixels reach past it (under MIS the camera takes those).
const char* kBox = R"(<scene version="3.0.0">
  <integrator type="path"/>
  <sensor type="perspective"><float name="fov" value="70"/>
    <transform name="to_world"><lookat origin="0,1,1.4" target="0,1.2,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/>
      <rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.75"/></bsdf>
  <shape type="cube"><transform name="to_world"><scale x="1.5" y="1" z="1.5"/><translate y="1"/></transform>
    <boolean name="flip_normals" value="true"/><ref id="white"/></shape>
  <shape type="cube"><transform name="to_world"><scale value="0.3"/><translate x="-0.5" y="0.3" z="-0.3"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.8,0.3,0.2"/></bsdf></shape>
  <shape type="cube"><transform name="to_world"><scale x="0.25" y="0.5" z="0.25"/><translate x="0.6" y="0.5" z="0.2"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.4,0.8"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.8" y="0.6"/><rotate x="1" angle="90"/><translate y="1.98"/></transform>
    <emitter type="area"><rgb name="radiance" value="4,4,4"/></emitter></shape>
</scene>)";

std::unique_ptr<Scene> box(const std::string& integrator, int max_depth) {
  LoadOptions o;
  o.integrator = integrator;
  LoadResult r = load_scene(parse_scene_string(kBox, "box.xml"), o);
  r.scene->integrator.max_depth = max_depth;
  r.scene->integrator.rr_depth = 1 << 20;  // (no roulette: the depths are short)
  return std::move(r.scene);
}

constexpr int kRenders = 16;
constexpr int kSpp = 32;

// The light of paths of exactly `depth` segments, by the path tracer.
Estimate path_light_of_depth(int depth) {
  auto longer = box("path", depth), shorter = box("path", depth - 1);
  return estimate_of(
      [&](uint32_t seed) {
        const Image a = render(*longer, render_settings(kSpp, seed)).to_image();
        const Image b = render(*shorter, render_settings(kSpp, seed)).to_image();
        Image d(a.width(), a.height(), 3);
        for (int y = 0; y < a.height(); ++y)
          for (int x = 0; x < a.width(); ++x)
            for (int c = 0; c < 3; ++c) d.at(x, y, c) = a.at(x, y, c) - b.at(x, y, c);
        return d;
      },
      kRenders, 8, 1);
}

Estimate strategy_alone(int s, int t) {
  auto scene = box("bdpt", s + t - 1);
  scene->integrator.only_s = s;
  scene->integrator.only_t = t;
  return estimate(*scene, kSpp, kRenders, 8, 1000 + uint32_t(10 * s + t));
}

TEST(BdptStrategy, EachStrategyAloneRendersItsPathLength) {
  for (int depth = 1; depth <= 3; ++depth) {
    const Estimate reference = path_light_of_depth(depth);
    for (int s = 0; s <= depth; ++s) {
      const int t = depth + 1 - s;
      if (t == 1 && s <= 1) continue;  // (s = 1, t = 1 is left out: s = 0 covers emitters seen directly)
      expect_agree(strategy_alone(s, t), reference, 6.0,
                   "strategy (" + std::to_string(s) + ", " + std::to_string(t) + ")", 0.01);
    }
  }
}

// Each strategy with its MIS weight (only_weighted, what `tessera render --strategy-images`
// writes): over every strategy bdpt has for paths up to the max depth, the images add up to the
// full render, pixel by pixel (up to float rounding: the full render sums a sample's strategies
// before the pixel's samples).
TEST(BdptStrategy, WeightedStrategiesSumToTheImage) {
  auto scene = box("bdpt", 3);
  const RenderSettings settings = render_settings(8, 5);
  const Image full = render(*scene, settings).to_image();
  Image sum(full.width(), full.height(), 3);
  const auto strategies = bdpt_strategies(3);
  EXPECT_EQ(strategies.size(), 8u) << "(0,2) (0,3) (1,2) (2,1) (0,4) (1,3) (2,2) (3,1)";
  for (const auto& [s, t] : strategies) {
    scene->integrator.only_s = s;
    scene->integrator.only_t = t;
    scene->integrator.only_weighted = true;
    const Image part = render(*scene, settings).to_image();
    for (int y = 0; y < full.height(); ++y)
      for (int x = 0; x < full.width(); ++x)
        for (int c = 0; c < 3; ++c) sum.at(x, y, c) += part.at(x, y, c);
  }
  double lit = 0;
  for (int y = 0; y < full.height(); ++y)
    for (int x = 0; x < full.width(); ++x)
      for (int c = 0; c < 3; ++c) {
        ASSERT_NEAR(sum.at(x, y, c), full.at(x, y, c), 1e-4f * full.at(x, y, c) + 1e-6f) << x << "," << y;
        lit += full.at(x, y, c);
      }
  EXPECT_GT(lit, 1.0);
}

}  // namespace
}  // namespace tessera
