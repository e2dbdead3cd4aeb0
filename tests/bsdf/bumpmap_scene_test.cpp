// bumpmap and normalmap through the scene loader: parameters, nested objects, errors; and a real
// bump map (the bathroom's floor tiles) on a small rendered scene.
#include "bsdf/perturbed_test_util.h"
#include "test_support.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"

#include "bsdf/bsdf_test_util.h"

#include <gtest/gtest.h>

#include <string>

namespace tessera {
namespace {

using test::direction_deg;

LoadResult load_06(const std::string& body, const std::string& dir = "mem") {
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", dir + "/bump.xml"), {});
}

/// A ramp h = slope * u (v constant) as a float EXR, so the file holds the values exactly.
std::string write_ramp_exr(const test::TempDir& dir, float slope) {
  Image im(64, 4, 3);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 64; ++x) im.set_rgb(x, y, Rgb(slope * (x + 0.5f) / 64.f));
  std::string path = (dir.path / "ramp.exr").string();
  write_image(path, im);
  return path;
}

const Bsdf* only_bsdf(const LoadResult& r) {
  EXPECT_TRUE(r.unsupported.empty());
  if (!r.scene || r.scene->shapes.empty()) return nullptr;
  return r.scene->shapes.at(0)->bsdf;
}

TEST(BumpMapScene, LoadsUnnamedScaledBitmapBesideUnnamedBsdf) {
  test::TempDir dir;
  std::string ramp = write_ramp_exr(dir, 0.25f);
  // Mitsuba 0.6's documented form: nothing named, the bitmap wrapped in `scale`.
  auto r = load_06(R"(<shape type="sphere"><bsdf type="bumpmap">
      <bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf>
      <texture type="scale"><float name="scale" value="2"/>
        <texture type="bitmap"><string name="filename" value=")" + ramp + R"("/>
          <string name="filterType" value="bilinear"/></texture></texture>
    </bsdf></shape>)");
  const Bsdf* b = only_bsdf(r);
  ASSERT_NE(b, nullptr);
  // Slope 2 * 0.25 along u: the normal leans by atan(0.5) towards -dp/du.
  SurfaceInteraction si = test::flat_si({0.5f, 0.5f});
  Vec3 n = normalize(Vec3(-0.5f, 0.f, 1.f));
  for (float deg : {0.f, 20.f, 40.f, 60.f}) {
    Vec3 wi = direction_deg(deg, 180.f);
    EXPECT_NEAR(b->eval(si, n, wi).g, std::max(0.f, dot(wi, n)) * kInvPi, 1e-5f) << deg;
  }
}

TEST(BumpMapScene, NamedMapAsInTheSharedScenes) {
  test::TempDir dir;
  std::string ramp = write_ramp_exr(dir, 0.5f);
  auto r = load_06(R"(<bsdf type="bumpmap" id="b"><texture name="map" type="bitmap">
      <string name="filename" value=")" + ramp + R"("/></texture>
      <bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf>
      <shape type="sphere"><ref id="b"/></shape>)");
  const Bsdf* b = only_bsdf(r);
  ASSERT_NE(b, nullptr);
  SurfaceInteraction si = test::flat_si({0.5f, 0.5f});
  Vec3 n = normalize(Vec3(-0.5f, 0.f, 1.f));
  EXPECT_NEAR(b->eval(si, n, n).g, 0.5f * kInvPi, 1e-5f);
}

TEST(BumpMapScene, RejectsMissingOrExtraChildren) {
  EXPECT_NE(test::scene_error_of([] { load_06(R"(<shape type="sphere"><bsdf type="bumpmap">
      <bsdf type="diffuse"/></bsdf></shape>)"); }).find("texture"), std::string::npos);
  EXPECT_NE(test::scene_error_of([] { load_06(R"(<shape type="sphere"><bsdf type="bumpmap">
      <texture type="checkerboard"/></bsdf></shape>)"); }).find("BSDF"), std::string::npos);
  EXPECT_NE(test::scene_error_of([] { load_06(R"(<shape type="sphere"><bsdf type="bumpmap">
      <texture type="checkerboard"/><bsdf type="diffuse"/><bsdf type="diffuse"/></bsdf></shape>)"); })
                .find("single"), std::string::npos);
  EXPECT_NE(test::scene_error_of([] { load_06(R"(<shape type="sphere"><bsdf type="normalmap">
      <texture name="map" type="checkerboard"/><bsdf type="diffuse"/></bsdf></shape>)"); })
                .find("normalmap"), std::string::npos);
}

TEST(BumpMapScene, NormalMapTextureNamedNormalmap) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="normalmap">
      <texture name="normalmap" type="checkerboard">
        <rgb name="color0" value="0.5, 0.5, 1"/><rgb name="color1" value="0.5, 0.5, 1"/></texture>
      <bsdf type="diffuse"><rgb name="reflectance" value="0.4"/></bsdf></bsdf></shape>)");
  const Bsdf* b = only_bsdf(r);
  ASSERT_NE(b, nullptr);
  SurfaceInteraction si = test::flat_si();
  Vec3 wo = direction_deg(20.f, 0.f), wi = direction_deg(35.f, 100.f);
  EXPECT_NEAR(b->eval(si, wo, wi).g, 0.4f * wi.z * kInvPi, 1e-6f);
}

// A 1 x 1 white diffuse square (its uvs span the tile texture once) under a constant sky of 1.
// Without the bump map every pixel is 0.8 exactly; the bump map can only lose energy (the tilted
// cosine lobe is clipped by the true horizon, some views fall behind the tilted normal), and the
// floor tiles are mostly flat, so most of it must remain.
Film render_tile_square(const std::string& tiles, bool bumped) {
  std::string diffuse = R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.8"/></bsdf>)";
  std::string bsdf = bumped ? R"(<bsdf type="bumpmap"><texture name="map" type="bitmap">
      <string name="filename" value=")" + tiles + R"("/><string name="filterType" value="trilinear"/>
      </texture>)" + diffuse + "</bsdf>"
                            : diffuse;
  auto r = load_scene(parse_scene_string(R"(<scene version="0.6.0">
    <integrator type="path"><integer name="maxDepth" value="4"/></integrator>
    <sensor type="perspective"><float name="fov" value="30"/>
      <transform name="toWorld"><lookat origin="0, 0, 2.5" target="0, 0, 0" up="0, 1, 0"/></transform>
      <sampler type="independent"><integer name="sampleCount" value="16"/></sampler>
      <film type="hdrfilm"><integer name="width" value="48"/><integer name="height" value="48"/></film>
    </sensor>
    <emitter type="constant"><float name="radiance" value="1"/></emitter>
    <shape type="rectangle">)" + bsdf + R"(</shape>
    </scene>)", "mem/tiles.xml"), {});
  EXPECT_TRUE(r.unsupported.empty());
  RenderSettings s;
  s.spp = 16;
  s.seed = 3;
  s.threads = 2;
  s.tile_size = 16;
  return render(*r.scene, s);
}

TEST(BumpMapScene, RealFloorTilesRender) {
  const std::string tiles = test::shared_path("scenes/bathroom/textures/floor_tiles.png");
  TESSERA_REQUIRE_FILE(tiles);
  Film flat = render_tile_square(tiles, false), bumped = render_tile_square(tiles, true);
  double sum_flat = 0, sum_bumped = 0;
  int n = 0;
  for (int y = 0; y < flat.height(); ++y)
    for (int x = 0; x < flat.width(); ++x) {
      Rgb a = flat.mean({x, y}), b = bumped.mean({x, y});
      ASSERT_TRUE(a.is_finite() && b.is_finite()) << x << "," << y;
      ASSERT_GE(b.g, 0.f);
      sum_flat += a.g;
      sum_bumped += b.g;
      ++n;
    }
  const double mean_flat = sum_flat / n, mean_bumped = sum_bumped / n;
  std::printf("[floor tiles] mean flat %.5f, bumped %.5f\n", mean_flat, mean_bumped);
  EXPECT_NEAR(mean_flat, 0.8, 5e-3);  // the camera sees the square only (MIS noise aside)
  EXPECT_LT(mean_bumped, mean_flat - 0.005);
  EXPECT_GT(mean_bumped, 0.5 * mean_flat);
}

}  // namespace
}  // namespace tessera
