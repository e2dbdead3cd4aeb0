// Sampling strategies of the path tracer (integrator.h): mis, bsdf and nee estimate the same image.
// Expected: on a scene with every kind of light path the strategies treat differently (area lights
// of two sizes, a point light, a constant sky, a perfect mirror, smooth plastic with its delta
// coat over a diffuse base, a rough conductor), the three renders agree within their own standard
// errors, over the whole image and per block; in closed forms (a point light or an emitting wall
// inside a diffuse sphere) each reaches the analytic value.
#include "scene_builders.h"
#include "tessera/render/integrator.h"
#include "tessera/render/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <vector>

namespace tessera {
namespace {

using namespace tessera::test;

constexpr SamplingStrategy kAll[] = {SamplingStrategy::Mis, SamplingStrategy::Bsdf, SamplingStrategy::Nee};

// An open box (floor, back and left walls) under a dim sky.
const char* kMixedScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <sensor type="perspective"><float name="fov" value="55"/>
    <transform name="to_world"><lookat origin="0,1.2,4.5" target="0,0.6,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
      <rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.6"/></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <ref id="grey"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><translate z="-2"/></transform>
    <ref id="grey"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate y="1" angle="90"/>
    <translate x="-2"/></transform><bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.2,0.2"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="-0.9" y="0.5" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="conductor"/></shape>
  <shape type="sphere"><point name="center" x="0.4" y="0.45" z="0.4"/><float name="radius" value="0.45"/>
    <bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2,0.3,0.7"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="1.3" y="0.4" z="-0.8"/><float name="radius" value="0.4"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.15"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.8" y="2.2" z="-0.5"/><float name="radius" value="0.25"/>
    <emitter type="area"><rgb name="radiance" value="12,10,8"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/>
    <translate x="-0.8" y="2.5" z="0.2"/></transform>
    <emitter type="area"><rgb name="radiance" value="4,4,5"/></emitter></shape>
  <emitter type="point"><point name="position" x="-1.2" y="1.8" z="1.5"/><rgb name="intensity" value="3"/></emitter>
  <emitter type="constant"><rgb name="radiance" value="0.3,0.35,0.4"/></emitter>
</scene>)";

std::unique_ptr<Scene> mixed_scene() {
  LoadResult r = load_scene(parse_scene_string(kMixedScene, "strategy_test.xml"), LoadOptions{});
  return std::move(r.scene);
}

// Mean and squared standard error of the mean of `film` over a block of pixels, per channel.
struct BlockStats {
  double mean[3] = {0, 0, 0}, se2[3] = {0, 0, 0};
};
BlockStats block_stats(const Film& film, int x0, int y0, int x1, int y1) {
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

bool same_bits(const Film& a, const Film& b) {
  for (int y = a.window().y0; y < a.window().y1; ++y)
    for (int x = a.window().x0; x < a.window().x1; ++x)
      if (std::memcmp(&a.pixel({x, y}), &b.pixel({x, y}), sizeof(PixelSums)) != 0) return false;
  return true;
}

TEST(SamplingStrategy, NamesRoundTrip) {
  for (SamplingStrategy s : kAll) {
    SamplingStrategy back = SamplingStrategy::Mis;
    ASSERT_TRUE(parse_sampling_strategy(sampling_strategy_name(s), back));
    EXPECT_EQ(back, s);
  }
  SamplingStrategy s;
  EXPECT_FALSE(parse_sampling_strategy("MIS", s));
  EXPECT_FALSE(parse_sampling_strategy("", s));
  EXPECT_EQ(IntegratorSettings{}.strategy, SamplingStrategy::Mis);
}

// Independent seeds per strategy so the z-scores' denominators (sum of the two variances) hold.
TEST(SamplingStrategy, AllThreeConvergeToTheSameImage) {
  auto scene = mixed_scene();
  ASSERT_TRUE(scene);
  std::vector<Film> films;
  for (size_t i = 0; i < 3; ++i) {
    scene->integrator.strategy = kAll[i];
    RenderStats stats;
    films.push_back(render(*scene, render_settings(1024, 11 + uint32_t(i)), {}, &stats));
    EXPECT_EQ(stats.counters.nonfinite, 0u) << sampling_strategy_name(kAll[i]);
  }
  // 8x8 blocks (12) plus the whole image, 3 channels, 3 pairs: 117 z-tests. |z| < 4 has a
  // two-sided probability of 6.3e-5 each, 0.0074 for all of them (Bonferroni): significance 0.01.
  const int w = films[0].width(), h = films[0].height();
  std::vector<std::array<int, 4>> blocks = {{0, 0, w, h}};
  for (int y = 0; y < h; y += 8)
    for (int x = 0; x < w; x += 8) blocks.push_back({x, y, x + 8, y + 8});
  for (const auto& bl : blocks) {
    BlockStats s[3];
    for (int i = 0; i < 3; ++i) s[i] = block_stats(films[size_t(i)], bl[0], bl[1], bl[2], bl[3]);
    for (int i = 0; i < 3; ++i)
      for (int j = i + 1; j < 3; ++j)
        for (int c = 0; c < 3; ++c) {
          double z = (s[i].mean[c] - s[j].mean[c]) / std::sqrt(s[i].se2[c] + s[j].se2[c] + 1e-30);
          EXPECT_LT(std::abs(z), 4.0) << sampling_strategy_name(kAll[i]) << " vs " << sampling_strategy_name(kAll[j])
                                      << " block (" << bl[0] << "," << bl[1] << ") channel " << c << ": "
                                      << s[i].mean[c] << " vs " << s[j].mean[c];
        }
  }
  // The whole image is lit (not a vacuous agreement of black images), and MIS is the least noisy
  // over the whole image: its standard error is below both single strategies'.
  BlockStats all[3];
  for (int i = 0; i < 3; ++i) all[i] = block_stats(films[size_t(i)], 0, 0, w, h);
  EXPECT_GT(all[0].mean[1], 0.05);
  EXPECT_LT(all[0].se2[1], all[1].se2[1]);
  EXPECT_LT(all[0].se2[1], all[2].se2[1]);
}

TEST(SamplingStrategy, StrategiesChangeTheSamplesButMisIsTheDefault) {
  auto scene = mixed_scene();
  RenderSettings s = render_settings(4, 3);
  Film by_default = render(*scene, s);
  scene->integrator.strategy = SamplingStrategy::Mis;
  EXPECT_TRUE(same_bits(by_default, render(*scene, s)));
  for (SamplingStrategy other : {SamplingStrategy::Bsdf, SamplingStrategy::Nee}) {
    scene->integrator.strategy = other;
    EXPECT_FALSE(same_bits(by_default, render(*scene, s))) << sampling_strategy_name(other);
  }
}

// Point light of intensity pi at the centre of a closed diffuse sphere (albedo 0.5): L = 1. BSDF
// sampling can never hit the point light: "bsdf" must keep next-event estimation for it.
TEST(SamplingStrategy, PointLightInSphereIsOneForEveryStrategy) {
  for (SamplingStrategy strategy : kAll) {
    auto scene = std::make_unique<Scene>();
    add_sphere(*scene, Vec3(0.f), 1.f, /*flip=*/true, add_diffuse(*scene, Rgb(0.5f)));
    scene->lights.push_back(make_point_light(Vec3(0.f), Rgb(kPi)));
    set_camera(*scene, Vec3(0.f), 70.f, 16, 12);
    scene->integrator.strategy = strategy;
    scene->finalize();
    BlockStats b = block_stats(render(*scene, render_settings(256)), 0, 0, 16, 12);
    for (int c = 0; c < 3; ++c)
      EXPECT_LT(std::abs(b.mean[c] - 1.0), 4.0 * std::sqrt(b.se2[c]) + 1e-4) << sampling_strategy_name(strategy);
  }
}

// The inside of a closed sphere that reflects (0.5) and emits (0.5): L = 0.5 / (1 - 0.5) = 1, from
// emitter hits only (bsdf), light samples plus the directly seen wall (nee), or both (mis).
TEST(SamplingStrategy, EmittingSphereIsOneForEveryStrategy) {
  for (SamplingStrategy strategy : kAll) {
    auto scene = std::make_unique<Scene>();
    Shape* shape = add_sphere(*scene, Vec3(0.f), 1.f, true, add_diffuse(*scene, Rgb(0.5f)));
    add_area_light(*scene, *shape, Rgb(0.5f));
    set_camera(*scene, Vec3(0.1f, -0.2f, 0.05f), 80.f, 16, 12);
    scene->integrator.strategy = strategy;
    scene->finalize();
    BlockStats b = block_stats(render(*scene, render_settings(256)), 0, 0, 16, 12);
    for (int c = 0; c < 3; ++c)
      EXPECT_LT(std::abs(b.mean[c] - 1.0), 4.0 * std::sqrt(b.se2[c]) + 1e-4) << sampling_strategy_name(strategy);
  }
}

}  // namespace
}  // namespace tessera
