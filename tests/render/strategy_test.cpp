// Sampling strategies of the path tracer (integrator.h): mis, bsdf and nee estimate the same image.
// Expected: on a scene with every kind of light path the strategies treat differently (area lights
// of two sizes, a point light, a constant sky, a perfect mirror, smooth plastic with its delta
// coat over a diffuse base, a rough conductor), the three renders agree within their own standard
// errors, over the whole image and per block; in closed forms (a point light or an emitting wall
// inside a diffuse sphere) each reaches the analytic value.
#include "image_agreement.h"
#include "scene_builders.h"
#include "tessera/render/integrator.h"
#include "tessera/sequence/renderer.h"
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
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j)
      (void)expect_same_expectation(films[size_t(i)], films[size_t(j)], 8, 4.0,
                                    std::string(sampling_strategy_name(kAll[i])) + " vs " + sampling_strategy_name(kAll[j]));
  const int w = films[0].width(), h = films[0].height();
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
