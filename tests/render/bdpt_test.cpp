// Bidirectional path tracing and light tracing (render/bdpt.h) converge to the path tracer's image.
// A bidirectional render's noise is partly in its splats, which a pixel's sample variance does not
// see, so each comparison estimates it from independent renders (seeds): the block means of K
// renders give a mean and its standard error with K - 1 degrees of freedom.
#include "image_agreement.h"
#include "independent_renders.h"
#include "scene_builders.h"
#include "tessera/render/bdpt.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

namespace tessera {
namespace {

using namespace tessera::test;

// A diffuse room with two glass balls, an area light and a dim sky through an opening: caustics a
// path tracer finds only by BSDF sampling, and light that reaches the camera through glass. (A
// point light's caustics are beyond the path tracer: PointLightInsideGlass.)
const char* kGlassScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <sensor type="perspective"><float name="fov" value="60"/>
    <transform name="to_world"><lookat origin="0,1,3.2" target="0,0.7,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/>
      <rfilter type="tent"/></film>
  </sensor>
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.7"/></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><translate z="-1.5"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate y="1" angle="90"/><translate x="-1.5"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2,0.6,0.2"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.3" y="0.45" z="0"/><float name="radius" value="0.45"/><bsdf type="dielectric"/></shape>
  <shape type="sphere"><point name="center" x="-0.8" y="1.2" z="-0.6"/><float name="radius" value="0.3"/><bsdf type="dielectric"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.3"/><rotate x="1" angle="90"/><translate x="0.6" y="2" z="-0.3"/></transform>
    <emitter type="area"><rgb name="radiance" value="10,9,8"/></emitter></shape>
  <emitter type="constant"><rgb name="radiance" value="0.2,0.25,0.3"/></emitter>
</scene>)";

constexpr int kRenders = 16;
constexpr double kTMax = 6.0;

TEST(Bdpt, ConvergesToPathOnTheMixedScene) {
  const Estimate path = estimate(*load_as(kMixedScene, "path"), 64, kRenders, 8, 100);
  const Estimate bdpt = estimate(*load_as(kMixedScene, "bdpt"), 16, kRenders, 8, 200);
  expect_agree(bdpt, path, kTMax, "bdpt vs path (mixed)");
}

TEST(Bdpt, ConvergesToPathThroughGlass) {
  const Estimate path = estimate(*load_as(kGlassScene, "path"), 128, kRenders, 6, 300);
  const Estimate bdpt = estimate(*load_as(kGlassScene, "bdpt"), 16, kRenders, 6, 400);
  expect_agree(bdpt, path, kTMax, "bdpt vs path (glass)");
}

TEST(Bdpt, ConvergesToPathThroughAWindowPane) {
  const Estimate path = estimate(*load_as(kWindowScene, "path"), 64, kRenders, 8, 500);
  const Estimate bdpt = estimate(*load_as(kWindowScene, "bdpt"), 16, kRenders, 8, 600);
  expect_agree(bdpt, path, kTMax, "bdpt vs path (window)");
}

// Leaving strategies out changes the weights of the others: each variant is its own estimator,
// and each converges to the same image only if the weights of every path sum to one. (Without
// both, the point light's direct light has no strategy left: a light image or next-event
// estimation must stay.)
TEST(Bdpt, EveryChoiceOfStrategiesConvergesToTheSameImage) {
  const Estimate path = estimate(*load_as(kGlassScene, "path"), 128, kRenders, 6, 700);
  for (const auto& [light_image, sample_direct] : {std::pair{false, true}, std::pair{true, false}}) {
    auto scene = load_as(kGlassScene, "bdpt");
    scene->integrator.light_image = light_image;
    scene->integrator.sample_direct = sample_direct;
    const Estimate bdpt = estimate(*scene, 16, kRenders, 6, 800);
    expect_agree(bdpt, path, kTMax,
                 std::string("bdpt lightImage=") + (light_image ? "on" : "off") + " sampleDirect=" + (sample_direct ? "on" : "off"));
  }
}

// The light tracer reaches every path that does not end at the camera through a delta lobe: on a
// diffuse scene (the glass scene with its balls made diffuse), all of them.
TEST(Ptracer, ConvergesToPathOnADiffuseScene) {
  std::string xml = kGlassScene;
  for (size_t at; (at = xml.find("<bsdf type=\"dielectric\"/>")) != std::string::npos;)
    xml.replace(at, 25, "<bsdf type=\"diffuse\"/>");
  const Estimate path = estimate(*load_as(xml.c_str(), "path"), 128, kRenders, 6, 900);
  const Estimate pt = estimate(*load_as(xml.c_str(), "ptracer"), 32, kRenders, 6, 1000);
  expect_agree(pt, path, kTMax, "ptracer vs path (diffuse)");
}

Image image_of(const Scene& scene, int threads, int tile_size) {
  RenderSettings s = render_settings(8, 7, tile_size);
  s.threads = threads;
  return render(scene, s).to_image();
}

bool same_image(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height()) return false;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x)
      for (int c = 0; c < 3; ++c)
        if (const float u = a.at(x, y, c), v = b.at(x, y, c); std::memcmp(&u, &v, sizeof(float)) != 0) return false;
  return true;
}

TEST(Bdpt, SameBitsForAnyThreadCountAndTileSize) {
  for (const char* integrator : {"bdpt", "ptracer"}) {
    auto scene = load_as(kGlassScene, integrator);
    const Image a = image_of(*scene, 1, 16), b = image_of(*scene, 2, 16), c = image_of(*scene, 2, 5);
    EXPECT_TRUE(same_image(a, b)) << integrator << ": 1 vs 2 threads";
    EXPECT_TRUE(same_image(a, c)) << integrator << ": tiles of 16 vs 5";
  }
}

TEST(Bdpt, RefusesWhatNeedsAPixelsOwnNoise) {
  auto scene = load_as(kGlassScene, "bdpt");
  RenderSettings s = render_settings(4);
  s.adaptive = true;
  EXPECT_THROW(render(*scene, s), std::invalid_argument);
  s = render_settings(4);
  s.target_error = 0.01;
  EXPECT_THROW(render(*scene, s), std::invalid_argument);
  s = render_settings(4);
  s.aovs = true;
  EXPECT_THROW(render(*scene, s), std::invalid_argument);
  s = render_settings(4);
  s.guiding = true;
  EXPECT_THROW(render(*scene, s), std::invalid_argument);
}

double green_mean(const Film& film) {
  double sum = 0;
  for (int y = film.window().y0; y < film.window().y1; ++y)
    for (int x = film.window().x0; x < film.window().x1; ++x) sum += film.mean({x, y}).g;
  return sum / double(film.window().area());
}

void expect_finite(const Film& film, const std::string& what) {
  for (int y = film.window().y0; y < film.window().y1; ++y)
    for (int x = film.window().x0; x < film.window().x1; ++x) ASSERT_TRUE(film.mean({x, y}).is_finite()) << what;
}

Film render_caged(const std::string& integrator, const std::string& extra, RenderStats* stats) {
  std::string xml = kCagedLightScene;
  xml.replace(xml.find("EXTRA"), 5, extra);
  return render(*load_as(xml.c_str(), integrator), render_settings(16, 3), {}, stats);
}

TEST(Bdpt, PointLightInsideGlassLightsTheRoom) {
  RenderStats stats;
  const double path = green_mean(render_caged("path", "", &stats));
  for (const char* integrator : {"bdpt", "ptracer"}) {
    const Film film = render_caged(integrator, "", &stats);
    expect_finite(film, integrator);
    EXPECT_EQ(stats.counters.nonfinite, 0u) << integrator;
    EXPECT_GT(green_mean(film), 0.02) << integrator;
    EXPECT_LT(path, green_mean(film) / 100) << "the path tracer cannot find this light";
  }
}

// Lights that emit nothing anywhere useful: facing away from everything, of zero power, of a
// vanishing area (a tiny light of huge radiance), behind the camera. Every image is finite and every sample counted.
TEST(Bdpt, DegenerateLightsGiveFiniteImages) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"facing away", R"(<shape type="rectangle"><transform name="to_world"><scale value="0.2"/><rotate x="1" angle="-90"/>
          <translate y="1.99"/></transform><emitter type="area"><rgb name="radiance" value="5"/></emitter></shape>)"},
      {"zero power", R"(<shape type="sphere"><point name="center" x="0.5" y="0.5" z="0"/><float name="radius" value="0.1"/>
          <emitter type="area"><rgb name="radiance" value="0"/></emitter></shape>)"},
      {"vanishing area", R"(<shape type="rectangle"><transform name="to_world"><scale x="1e-6" y="1e-6"/><translate y="1"/></transform>
          <emitter type="area"><rgb name="radiance" value="1e12"/></emitter></shape>)"},
      {"behind the camera", R"(<emitter type="spot"><transform name="to_world"><lookat origin="0,1,1.45" target="0,1,3"/></transform>
          <rgb name="intensity" value="5"/></emitter>)"},
  };
  for (const auto& [what, extra] : cases)
    for (const char* integrator : {"bdpt", "ptracer"}) {
      RenderStats stats;
      const Film film = render_caged(integrator, extra, &stats);
      expect_finite(film, what + " " + integrator);
      EXPECT_EQ(stats.counters.nonfinite, 0u) << what << " " << integrator;
      EXPECT_GT(green_mean(film), 0.02) << what << " " << integrator << ": the caged light still lights the room";
    }
}

}  // namespace
}  // namespace tessera
