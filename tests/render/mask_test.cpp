// Mitsuba's `mask`: rays pass a masked surface with probability 1 - opacity (a binomial / chi-square
// test on the choice), shadow rays are attenuated by exactly 1 - opacity, and rendered images match
// the closed-form value of a masked plane in a constant environment.
#include "scene_builders.h"
#include "test_support.h"
#include "tessera/bsdf/mask.h"
#include "tessera/core/hash.h"
#include "tessera/image/image.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/texture/bitmap.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

using namespace tessera::test;

std::shared_ptr<MeshData> quad_at_z(float z, float half) {
  auto m = std::make_shared<MeshData>();
  m->positions = {{-half, -half, z}, {half, -half, z}, {half, half, z}, {-half, half, z}};
  m->indices = {0, 1, 2, 0, 2, 3};
  return m;
}

const Bsdf* add_mask(Scene& scene, const Bsdf* nested, float opacity) {
  auto b = make_mask_bsdf(nested, std::make_shared<ConstantTexture>(Rgb(opacity)));
  scene.bsdfs.push_back(b);
  return b.get();
}

void add_quad(Scene& scene, float z, float half, const Bsdf* bsdf) {
  scene.shapes.push_back(std::make_unique<TriangleMeshShape>(quad_at_z(z, half), false, false));
  scene.shapes.back()->bsdf = bsdf;
}

// Two masked quads (opacity 0.3 at z=1, 0.5 at z=2) in front of an opaque one at z=3.
std::unique_ptr<Scene> stacked_quads() {
  auto scene = std::make_unique<Scene>();
  const Bsdf* diffuse = add_diffuse(*scene, Rgb(0.5f));
  add_quad(*scene, 1.f, 10.f, add_mask(*scene, diffuse, 0.3f));
  add_quad(*scene, 2.f, 10.f, add_mask(*scene, diffuse, 0.5f));
  add_quad(*scene, 3.f, 10.f, diffuse);
  scene->finalize();
  return scene;
}

TEST(Mask, RaysStopAtEachLayerWithItsOpacity) {
  auto scene = stacked_quads();
  ASSERT_TRUE(scene->has_masks());
  Pcg32 rng(7);
  const int n = 30000;
  int counts[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    Ray r;
    r.o = Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, 0.f);
    r.d = normalize(Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, 1.f));
    SurfaceInteraction si;
    ASSERT_TRUE(scene->intersect(r, si));
    int layer = int(std::lround(si.p.z)) - 1;
    ASSERT_TRUE(layer >= 0 && layer < 3) << si.p.z;
    // si.t is measured from the original origin even after passing through masks.
    EXPECT_NEAR(si.t, (si.p.z - r.o.z) / r.d.z, 1e-4f * si.t);
    ++counts[layer];
  }
  // Expected: 0.3, 0.7 * 0.5, 0.7 * 0.5. Chi-square with 2 degrees of freedom at 0.01: 9.21.
  const double expected[3] = {0.3 * n, 0.35 * n, 0.35 * n};
  double chi2 = 0;
  for (int k = 0; k < 3; ++k) chi2 += (counts[k] - expected[k]) * (counts[k] - expected[k]) / expected[k];
  EXPECT_LT(chi2, 9.21) << counts[0] << " " << counts[1] << " " << counts[2];
}

TEST(Mask, ShadowRaysAreAttenuatedByOneMinusOpacity) {
  auto scene = stacked_quads();
  Ray through_masks = spawn_ray_to(Vec3(0.f, 0.f, 0.f), Vec3(0.f, 0.f, 1.f), Vec3(0.3f, 0.1f, 2.5f));
  EXPECT_NEAR(scene->transmittance(through_masks), 0.7f * 0.5f, 1e-6f);
  Ray to_first = spawn_ray_to(Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.2f, 1.5f));
  EXPECT_NEAR(scene->transmittance(to_first), 0.7f, 1e-6f);
  Ray past_opaque = spawn_ray_to(Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.f, 4.f));
  EXPECT_EQ(scene->transmittance(past_opaque), 0.f);
  Ray away = spawn_ray(Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.f, -1.f));
  EXPECT_EQ(scene->transmittance(away), 1.f);
  // Without masks the same calls are plain visibility.
  Scene opaque;
  add_quad(opaque, 1.f, 10.f, add_diffuse(opaque, Rgb(0.5f)));
  opaque.finalize();
  EXPECT_FALSE(opaque.has_masks());
  EXPECT_EQ(opaque.transmittance(to_first), 0.f);
}

// Shadow rays through a scene whose cut-outs are all meshes take one any-hit query; with a masked
// sphere (crossed twice) the scene takes the loop of closest hits. Both give the same product,
// also past the cap of 64 crossings, where the next cut-out counts as opaque.
TEST(Mask, OneAnyHitQueryCrossesCutOutsAsTheClosestHitLoopDoes) {
  auto build = [](bool with_masked_sphere, int layers) {
    auto scene = std::make_unique<Scene>();
    const Bsdf* diffuse = add_diffuse(*scene, Rgb(0.5f));
    for (int k = 0; k < layers; ++k) add_quad(*scene, 1.f + 0.25f * k, 1.f + 0.5f * k, add_mask(*scene, diffuse, 0.02f + 0.013f * (k % 7)));
    add_quad(*scene, 1.f + 0.25f * layers, 3.f, diffuse);  // an opaque patch behind them
    if (with_masked_sphere) add_sphere(*scene, Vec3(0.f, 0.f, -50.f), 1.f, false, add_mask(*scene, diffuse, 0.5f));
    scene->finalize();
    return scene;
  };
  for (int layers : {5, 65}) {
    auto any_hit = build(false, layers), loop = build(true, layers);
    Pcg32 rng(19);
    int attenuated = 0, blocked = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 from(2.f * rng.next_float() - 1.f, 2.f * rng.next_float() - 1.f, 0.f);
      const Vec3 to(16.f * rng.next_float() - 8.f, 16.f * rng.next_float() - 8.f, 1.f + 0.25f * layers + 1.f);
      const Ray r = spawn_ray_to(from, Vec3(0.f, 0.f, 1.f), to);
      const float a = any_hit->transmittance(r), b = loop->transmittance(r);
      ASSERT_NEAR(a, b, 1e-6f * std::max(b, 1e-3f)) << "ray " << i << ", " << layers << " layers";
      attenuated += a > 0.f && a < 1.f;
      blocked += a == 0.f;
    }
    EXPECT_GT(blocked, 100);  // by the opaque patch, or (65 layers) by the cap
    if (layers == 5) EXPECT_GT(attenuated, 100);
  }
}

TEST(Mask, NanOpacityIsOpaqueAndValuesAreClamped) {
  Scene scene;
  const Bsdf* diffuse = add_diffuse(scene, Rgb(0.5f));
  SurfaceInteraction si;
  EXPECT_EQ(add_mask(scene, diffuse, std::nanf(""))->opacity(si), 1.f);
  EXPECT_EQ(add_mask(scene, diffuse, 2.f)->opacity(si), 1.f);
  EXPECT_EQ(add_mask(scene, diffuse, -1.f)->opacity(si), 0.f);
  // The opaque part is the nested BSDF itself.
  const Bsdf* m = add_mask(scene, diffuse, 0.25f);
  Vec3 wo = normalize(Vec3(0.2f, 0.1f, 1.f)), wi = normalize(Vec3(-0.3f, 0.4f, 0.8f));
  EXPECT_EQ(m->eval(si, wo, wi).g, diffuse->eval(si, wo, wi).g);
  EXPECT_EQ(m->pdf(si, wo, wi), diffuse->pdf(si, wo, wi));
}

LoadResult load_06(const std::string& body) {
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/mask.xml"), {});
}

const char* kCamera = R"(
  <sensor type="perspective"><float name="fov" value="20"/>
    <transform name="toWorld"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sampleCount" value="64"/></sampler>
    <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/>
      <rfilter type="box"/></film>
  </sensor>)";

double mean_of(const Film& film) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x, ++n) sum += film.mean({x, y}).average();
  return sum / n;
}

// A plane of albedo rho and opacity a facing the camera, in a constant environment of radiance 1:
// the plane's lit side reflects rho (irradiance pi from the open hemisphere), so a pixel sees
// a * rho + (1 - a). 0.3 * 0.5 + 0.7 = 0.85; an unmasked plane would give 0.5, swapped opacity 0.65.
TEST(Mask, MaskedPlaneInConstantEnvironmentMatchesClosedForm) {
  LoadResult r = load_06(std::string("<integrator type=\"path\"/>") + kCamera + R"(
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <shape type="rectangle"><transform name="toWorld"><scale value="3"/></transform>
      <bsdf type="mask"><float name="opacity" value="0.3"/>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></bsdf>
    </shape>)");
  ASSERT_TRUE(r.unsupported.empty());
  RenderSettings s;
  s.spp = 256;
  s.seed = 3;
  RenderStats stats;
  Film film = render(*r.scene, s, {}, &stats);
  // Per-sample standard deviation is at most ~0.5 (a Bernoulli choice between 0.5 and 1 plus the
  // diffuse estimate); 144 pixels x 256 samples: standard error < 0.002.
  EXPECT_NEAR(mean_of(film), 0.85, 0.006);
  EXPECT_EQ(stats.counters.nonfinite, 0u);
}

// Direct light only, through a masked occluder behind the camera: every pixel of the floor gets
// exactly (1 - opacity) of the light it gets with no occluder (same samples, a point light).
TEST(Mask, ShadowOfMaskedOccluderScalesDirectLightExactly) {
  auto floor_scene = [](const std::string& occluder) {
    return load_06(R"(<integrator type="path"><integer name="maxDepth" value="2"/></integrator>
      <sensor type="perspective"><float name="fov" value="60"/>
        <transform name="toWorld"><lookat origin="0,0,0.5" target="0,0,0" up="0,1,0"/></transform>
        <sampler type="independent"><integer name="sampleCount" value="4"/></sampler>
        <film type="hdrfilm"><integer name="width" value="10"/><integer name="height" value="10"/>
          <rfilter type="box"/></film>
      </sensor>
      <emitter type="point"><point name="position" x="0" y="0" z="2"/><rgb name="intensity" value="5"/></emitter>
      <shape type="rectangle"><transform name="toWorld"><scale value="10"/></transform>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>)" + occluder);
  };
  const std::string quad = R"(<shape type="rectangle"><transform name="toWorld"><scale value="0.5"/>
      <translate z="1"/></transform>)";
  LoadResult open = floor_scene("");
  LoadResult masked = floor_scene(quad + R"(<bsdf type="mask"><float name="opacity" value="0.4"/>
      <bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf></shape>)");
  LoadResult opaque = floor_scene(quad + "<bsdf type=\"diffuse\"/></shape>");
  RenderSettings s;
  s.spp = 4;
  Film f_open = render(*open.scene, s), f_masked = render(*masked.scene, s), f_opaque = render(*opaque.scene, s);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 10; ++x) {
      float lit = f_open.mean({x, y}).g;
      ASSERT_GT(lit, 0.f);
      EXPECT_NEAR(f_masked.mean({x, y}).g / lit, 0.6f, 1e-5f) << x << "," << y;
      EXPECT_EQ(f_opaque.mean({x, y}).g, 0.f);
    }
}

// An RGBA bitmap as opacity: Mitsuba (0.6 and 3) uses its colour's luminance; its alpha only when
// the bitmap asks for `channel` "a". The living room's leaf.png is white where alpha is 0, so the
// two readings differ there (and its Mitsuba 3 reference follows the colour).
TEST(Mask, RgbaBitmapOpacityIsItsLuminanceUnlessChannelA) {
  const std::string leaf = shared_path("scenes/living-room/textures/leaf.png");
  TESSERA_REQUIRE_FILE(leaf);
  auto load_mask = [&](const std::string& channel) {
    return load_06(R"(<shape type="rectangle"><bsdf type="mask">
      <texture name="opacity" type="bitmap"><string name="filename" value=")" + leaf + "\"/>" + channel +
                   R"(</texture><bsdf type="diffuse"/></bsdf></shape>)");
  };
  LoadResult by_colour = load_mask("");
  LoadResult by_alpha = load_mask(R"(<string name="channel" value="a"/>)");
  ASSERT_TRUE(by_colour.unsupported.empty());
  ASSERT_TRUE(by_alpha.unsupported.empty());
  const Bsdf* colour_mask = by_colour.scene->shapes.at(0)->bsdf;
  const Bsdf* alpha_mask = by_alpha.scene->shapes.at(0)->bsdf;
  ASSERT_TRUE(colour_mask && colour_mask->has_opacity() && alpha_mask && alpha_mask->has_opacity());
  Image img = read_image(leaf).linearized();
  ASSERT_EQ(img.channels(), 4);
  int seen_clear = 0, seen_solid = 0, seen_white = 0;
  for (int y = 1; y + 1 < img.height(); y += 7)
    for (int x = 1; x + 1 < img.width(); x += 7) {
      // Only texels whose neighbours agree, so the bilinear lookup at the centre is that texel.
      bool alpha_uniform = true, colour_uniform = true;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          alpha_uniform = alpha_uniform && img.at(x + dx, y + dy, 3) == img.at(x, y, 3);
          for (int c = 0; c < 3; ++c) colour_uniform = colour_uniform && img.at(x + dx, y + dy, c) == img.at(x, y, c);
        }
      const float a = img.at(x, y, 3);
      if (!alpha_uniform || (a != 0.f && a != 1.f)) continue;
      SurfaceInteraction si;
      si.uv = Vec2((x + 0.5f) / img.width(), (y + 0.5f) / img.height());
      si.wo = si.shading.n;
      EXPECT_NEAR(alpha_mask->opacity(si), a, 1e-6f) << x << "," << y;
      (a == 0.f ? seen_clear : seen_solid)++;
      if (!colour_uniform) continue;
      const float luminance = img.rgb(x, y).luminance();
      EXPECT_NEAR(colour_mask->opacity(si), std::min(luminance, 1.f), 1e-5f) << x << "," << y;
      if (a == 0.f) {
        EXPECT_GT(luminance, 0.9f) << "leaf.png is white where it is clear";
        ++seen_white;
      }
    }
  EXPECT_GT(seen_white, 20);
  EXPECT_GT(seen_clear, 20);
  EXPECT_GT(seen_solid, 20);
}

TEST(Mask, BitmapChannelErrorsNameTheFileAndLine) {
  const std::string leaf = shared_path("scenes/living-room/textures/leaf.png");
  TESSERA_REQUIRE_FILE(leaf);
  std::string msg = scene_error_of([&] {
    (void)load_06(R"(<shape type="rectangle"><bsdf type="diffuse"><texture name="reflectance" type="bitmap">
      <string name="filename" value=")" + leaf + R"("/><string name="channel" value="q"/></texture></bsdf></shape>)");
  });
  EXPECT_NE(msg.find("mem/mask.xml:3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("unknown channel 'q'"), std::string::npos) << msg;
}

}  // namespace
}  // namespace tessera
