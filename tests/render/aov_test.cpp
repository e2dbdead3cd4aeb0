// AOVs (render/aov.h) against closed forms: the albedo of a diffuse plane, the normals of a sphere,
// the depth of a plane, features followed through a perfect mirror; the same bits for any tiling,
// the beauty image unchanged by asking for them; half A and half B independent.
#include "scene_builders.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

namespace tessera {
namespace {

using namespace tessera::test;

// A camera at the origin looking down -z at a diffuse rectangle (z = -3, 8 × 8) and, behind the
// camera, a mirror-facing diffuse rectangle; `front` is the BSDF of the first. Lit by a sky.
std::unique_ptr<Scene> plane_scene(const std::string& front, const std::string& sampler = "independent") {
  const std::string xml = R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,0,0" target="0,0,-1" up="0,1,0"/></transform>
    <sampler type=")" + sampler + R"("><integer name="sample_count" value="8"/></sampler>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="16"/>
      <rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="4"/><translate z="-3"/></transform>)" +
                          front + R"(</shape>
  <shape type="rectangle"><transform name="to_world"><scale value="4"/><rotate y="1" angle="180"/>
    <translate z="2"/></transform><bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.4,0.8"/></bsdf></shape>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
</scene>)";
  return load_scene(parse_scene_string(xml, "plane.xml"), LoadOptions{}).scene;
}

RenderSettings aov_settings(int spp, int tile_size = 8) {
  RenderSettings s = render_settings(spp, 3, tile_size);
  s.aovs = true;
  return s;
}

Vec3 at(const Image& img, int x, int y) { return {img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2)}; }

// The pixel's mean depth of the plane z = -z_plane must lie between the plane's distance and the
// largest distance over the pixel, which a corner has (1/cos is convex).
void expect_plane_depth(const Scene& scene, const Image& depth, int x, int y, float z_plane) {
  float far = 0.f;
  for (Vec2 corner : {Vec2(0.f, 0.f), Vec2(1.f, 0.f), Vec2(0.f, 1.f), Vec2(1.f, 1.f)}) {
    const Vec3 d = normalize(scene.camera->generate_ray(Vec2(x + corner.x, y + corner.y), {}).d);
    far = std::max(far, z_plane / -d.z);
  }
  EXPECT_GE(depth.at(x, y, 0), z_plane * (1.f - 1e-5f)) << x << "," << y;
  EXPECT_LE(depth.at(x, y, 0), far * (1.f + 1e-5f)) << x << "," << y;
}

// Every pixel of the plane scene with `front` sees the albedo `albedo`, a normal of z `normal_z` and
// the depth of the plane at z = -3.
void expect_plane_features(const std::string& front, Vec3 albedo, float normal_z) {
  auto scene = plane_scene(front);
  const Film film = render(*scene, aov_settings(8));
  const Image a = film.aov_image(AovLayer::Albedo), n = film.aov_image(AovLayer::Normal),
              depth = film.aov_image(AovLayer::Depth);
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      EXPECT_NEAR(length(at(a, x, y) - albedo), 0.f, 2e-5f) << x << "," << y;
      EXPECT_NEAR(at(n, x, y).z, normal_z, 1e-5f);
      expect_plane_depth(*scene, depth, x, y, 3.f);
    }
}

TEST(Aovs, DiffusePlaneAlbedoNormalAndDepth) {
  expect_plane_features(R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.3,0.5,0.7"/></bsdf>)",
                        Vec3(0.3f, 0.5f, 0.7f), 1.f);
}

TEST(Aovs, FeaturesFollowAPerfectMirror) {
  // The mirror (reflectance 0.5) at z = -3 shows the plane at z = 2 behind the camera: the albedo is
  // 0.5 × its reflectance, the normal its normal (+z facing the mirror is -z), the depth the mirror's.
  expect_plane_features(R"(<bsdf type="conductor"><string name="material" value="none"/>
      <rgb name="specular_reflectance" value="0.5"/></bsdf>)", Vec3(0.1f, 0.2f, 0.4f), -1.f);
}

TEST(Aovs, SphereNormalsAndEscapedPaths) {
  Scene scene;
  add_sphere(scene, {0.f, 0.f, 4.f}, 1.f, false, add_diffuse(scene, Rgb(0.5f)));
  set_camera(scene, {0.f, 0.f, 0.f}, 40.f, 48, 48);
  scene.finalize();
  const Film film = render(scene, aov_settings(4));
  const Image normal = film.aov_image(AovLayer::Normal), albedo = film.aov_image(AovLayer::Albedo),
              depth = film.aov_image(AovLayer::Depth);
  int covered = 0, empty = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 48; ++x) {
      const auto shape = cover(scene, x, y);
      if (!shape) continue;  // a silhouette
      if (*shape == nullptr) {
        EXPECT_EQ(at(normal, x, y).x, 0.f);
        EXPECT_EQ(at(albedo, x, y).y, 0.f);
        EXPECT_EQ(depth.at(x, y, 0), 0.f);
        ++empty;
        continue;
      }
      SurfaceInteraction si;
      ASSERT_TRUE(scene.intersect(scene.camera->generate_ray(Vec2(x + 0.5f, y + 0.5f), {}), si));
      const Vec3 expected = normalize(si.p - Vec3(0.f, 0.f, 4.f)), got = at(normal, x, y);
      EXPECT_GT(dot(normalize(got), expected), 0.999f) << x << "," << y;
      EXPECT_GT(length(got), 0.99f);  // a mean of unit normals that barely differ
      ++covered;
    }
  EXPECT_GT(covered, 200);
  EXPECT_GT(empty, 200);
}

bool same_aov_bits(const Film& a, const Film& b) {
  for (int y = a.window().y0; y < a.window().y1; ++y)
    for (int x = a.window().x0; x < a.window().x1; ++x)
      if (std::memcmp(&a.aov({x, y}), &b.aov({x, y}), sizeof(AovSums)) != 0 ||
          std::memcmp(&a.pixel({x, y}), &b.pixel({x, y}), sizeof(PixelSums)) != 0)
        return false;
  return true;
}

TEST(Aovs, SameBitsForAnyTilingAndTheBeautyUnchanged) {
  auto scene = mixed_scene();
  RenderSettings s = aov_settings(6, 5);
  s.threads = 1;
  const Film ref = render(*scene, s);
  s.threads = 2;
  s.tile_size = 16;
  EXPECT_TRUE(same_aov_bits(ref, render(*scene, s)));
  s.seed = 4;
  EXPECT_FALSE(same_aov_bits(ref, render(*scene, s)));  // so the comparison can fail

  s.seed = 3;
  s.aovs = false;
  const Film plain = render(*scene, s);
  for (int y = 0; y < plain.height(); ++y)
    for (int x = 0; x < plain.width(); ++x)
      ASSERT_EQ(std::memcmp(&plain.pixel({x, y}), &ref.pixel({x, y}), sizeof(PixelSums)), 0);
}

// E[(A - B)^2] against Var A + Var B over many pixels, both from the pixels' own samples: A, B are
// the halves' means, each variance the sample variance over the half's count. Returns the ratio.
double halves_ratio(const Film& film) {
  const Image a = film.aov_image(AovLayer::HalfA), b = film.aov_image(AovLayer::HalfB);
  double diff = 0, var = 0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      const PixelSums& p = film.pixel({x, y});
      const AovSums& h = film.aov({x, y});
      const Rgb s2 = film.sample_variance({x, y});
      for (int c = 0; c < 3; ++c) {
        const double d = double(a.at(x, y, c)) - double(b.at(x, y, c));
        diff += d * d;
        var += s2[c] / double(h.half_count) + s2[c] / double(p.count - h.half_count);
      }
    }
  return diff / var;
}

// The diffuse plane under the sky: every sample bounded, so the ratio of sums is not at the mercy of
// a few fireflies (in the mixed scene it ranges from 0.5 to 2.5 between seeds).
double plane_halves_ratio(const std::string& sampler) {
  auto scene = plane_scene(R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.3,0.5,0.7"/></bsdf>)", sampler);
  RenderSettings s = aov_settings(16);
  double ratio = 0;
  for (uint32_t seed = 1; seed <= 8; ++seed) {
    s.seed = seed;
    ratio += halves_ratio(render(*scene, s)) / 8;
  }
  return ratio;
}

TEST(Aovs, HalvesAreIndependentUnderTheIndependentSampler) {
  const double ratio = plane_halves_ratio("independent");
  std::printf("independent: E[(A-B)^2] / (Var A + Var B) = %.3f\n", ratio);
  // 4 × 768 pixels of 16 samples: independent halves give 1 within a few percent.
  EXPECT_NEAR(ratio, 1.0, 0.1);
}

TEST(Aovs, HalvesUnderSobolDifferByTheirPairsStratification) {
  const double ratio = plane_halves_ratio("sobol");
  std::printf("Sobol: E[(A-B)^2] / (Var A + Var B) = %.3f\n", ratio);
  // Each pair (2k, 2k+1) is stratified against itself, so A - B varies more than two independent
  // halves' difference; bounded, so a denoiser's error estimate from the halves is conservative.
  EXPECT_GT(ratio, 0.95);
  EXPECT_LT(ratio, 1.6);
}

TEST(Aovs, LayerNames) {
  EXPECT_EQ(parse_aov_layers("albedo,depth")->size(), 2u);
  EXPECT_EQ(parse_aov_layers("all")->size(), size_t(kAovLayerCount));
  std::string error;
  EXPECT_FALSE(parse_aov_layers("albedo,shine", &error));
  EXPECT_NE(error.find("'shine'"), std::string::npos);
  EXPECT_EQ(aov_channel_names(AovLayer::Normal), (std::vector<std::string>{"X", "Y", "Z"}));
}

}  // namespace
}  // namespace tessera
