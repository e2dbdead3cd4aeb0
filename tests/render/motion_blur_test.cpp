// Motion blur: a sphere moving across an orthographic view covers each pixel centre for the
// analytic fraction of the shutter; scenes where nothing moves render exactly as without motion.
#include "scene_builders.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace tessera {
namespace {

constexpr int kW = 64, kH = 16, kSpp = 2048;
constexpr float kHalfWidth = 2.f;  // orthographic extent: camera x in [-2, 2], y in [-0.5, 0.5]
constexpr float kRadius = 0.4f, kX0 = -1.2f, kX1 = 0.8f;  // sphere centre x at shutter open / close

// A black sphere in front of a constant environment of radiance 1, seen directly (maxDepth 1):
// a pixel's value is 1 - (fraction of the shutter the sphere covers its centre). The box filter
// of radius 1e-4 keeps every sample at the pixel centre.
const std::string kStaticCamera = R"(<transform name="toWorld"><scale x="2" y="2"/></transform>)";

std::string scene_xml(const std::string& sphere, float shutter_close, const std::string& camera = kStaticCamera) {
  return R"(<scene version="0.6.0">
    <integrator type="path"><integer name="maxDepth" value="1"/></integrator>
    <sensor type="orthographic">
      <float name="shutterOpen" value="0"/><float name="shutterClose" value=")" + std::to_string(shutter_close) + R"("/>
      )" + camera + R"(
      <sampler type="independent"><integer name="sampleCount" value=")" + std::to_string(kSpp) + R"("/></sampler>
      <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="16"/>
        <rfilter type="box"><float name="radius" value="0.0001"/></rfilter></film>
    </sensor>
    <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
    <bsdf type="diffuse" id="black"><rgb name="reflectance" value="0"/></bsdf>
    )" + sphere + "</scene>";
}

Film render_xml(const std::string& xml, uint32_t seed = 7) {
  LoadOptions o;
  auto scene = load_scene(parse_scene_string(xml, "mem/motion.xml"), o).scene;
  RenderSettings rs;
  rs.spp = kSpp;
  rs.seed = seed;
  rs.threads = 2;
  return render(*scene, rs);
}

// Shutter fraction during which a sphere sliding along x from x0 to x1 (over the shutter [0, 1])
// covers the ray through camera-space (X, Y): |X - c(t)| < sqrt(r^2 - Y^2), c(t) linear.
double covered_fraction(double X, double Y) {
  double h2 = double(kRadius) * kRadius - Y * Y;
  if (h2 <= 0) return 0;
  double hw = std::sqrt(h2), v = double(kX1) - kX0;
  double t0 = std::clamp((X - hw - kX0) / v, 0.0, 1.0), t1 = std::clamp((X + hw - kX0) / v, 0.0, 1.0);
  return t1 - t0;
}

void expect_analytic_coverage(const Film& film) {
  int partial = 0;
  double sum_err = 0, sum_sigma2 = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      // Orthographic convention: camera x = s (1 - 2 sx), y = s (1 - 2 sy) / aspect.
      const double X = kHalfWidth * (1.0 - 2.0 * (x + 0.5) / kW);
      const double Y = kHalfWidth * (1.0 - 2.0 * (y + 0.5) / kH) * kH / kW;
      const double f = covered_fraction(X, Y);
      const double value = film.mean({x, y}).g;
      // Binomial noise of kSpp independent times; a floor for fractions at 0 or 1.
      const double sigma = std::sqrt(std::max(f * (1 - f), 1e-4) / kSpp);
      EXPECT_NEAR(value, 1.0 - f, 4.5 * sigma) << "pixel " << x << "," << y << " covered " << f;
      if (f > 0 && f < 1) ++partial;
      sum_err += value - (1.0 - f);
      sum_sigma2 += f * (1 - f) / kSpp;
    }
  EXPECT_GT(partial, 100);  // the blur streak spans many pixels
  // The summed error over the streak: no bias beyond 6 binomial sigmas of the total (the sums of
  // hash-seeded pixels spread about twice as wide as independent binomials would: seeds 7, 11-14
  // give -0.9 .. +0.1 at sigma 0.21). A speed off by 2.5% moves the sum by ~2.5.
  EXPECT_LT(std::abs(sum_err), 6.0 * std::sqrt(sum_sigma2));
}

const std::string kSlidingSphere = R"(<shape type="sphere"><float name="radius" value="0.4"/>
      <point name="center" x="-1.2" y="0" z="5"/><point name="centerClose" x="0.8" y="0" z="5"/>
      <ref id="black"/></shape>)";

TEST(MotionBlur, SlidingSphereCoversPixelsForTheAnalyticFraction) {
  expect_analytic_coverage(render_xml(scene_xml(kSlidingSphere, 1.f)));
}

TEST(MotionBlur, AnimatedToWorldMatchesTheAnalyticFraction) {
  const std::string sphere = R"(<shape type="sphere"><float name="radius" value="0.4"/>
      <animation name="toWorld">
        <transform time="0"><translate x="-1.2" y="0" z="5"/></transform>
        <transform time="1"><translate x="0.8" y="0" z="5"/></transform>
      </animation><ref id="black"/></shape>)";
  expect_analytic_coverage(render_xml(scene_xml(sphere, 1.f)));
}

// The camera moving the other way past a still sphere: the same relative motion, so the same
// analytic coverage (camera x from 1.2 to -0.8 while the sphere stays at x = 0).
TEST(MotionBlur, AnimatedCameraMatchesTheAnalyticFraction) {
  const std::string still = R"(<shape type="sphere"><float name="radius" value="0.4"/>
      <point name="center" x="0" y="0" z="5"/><ref id="black"/></shape>)";
  const std::string moving_camera = R"(<animation name="toWorld">
        <transform time="0"><scale x="2" y="2"/><translate x="1.2"/></transform>
        <transform time="1"><scale x="2" y="2"/><translate x="-0.8"/></transform>
      </animation>)";
  expect_analytic_coverage(render_xml(scene_xml(still, 1.f, moving_camera)));
}

// The same motion through an animated instance of a shapegroup gives the same bits as the shape's
// own animation (the same world_from_object at every time).
TEST(MotionBlur, AnimatedInstanceEqualsAnimatedShape) {
  const std::string anim = R"(<animation name="toWorld">
        <transform time="0"><rotate z="1" angle="-20"/><translate x="-1.2" y="0" z="5"/></transform>
        <transform time="1"><rotate z="1" angle="30"/><translate x="0.8" y="0.1" z="5"/></transform>
      </animation>)";
  const std::string cube = R"(<shape type="cube"><transform name="toWorld"><scale value="0.3"/></transform><ref id="black"/></shape>)";
  const std::string grouped = "<shapegroup id=\"g\">" + cube + "</shapegroup><shape type=\"instance\"><ref id=\"g\"/>" + anim + "</shape>";
  // The direct form: the instance's animation times the shape's static scale.
  const std::string animated_scaled = R"(<shape type="cube"><animation name="toWorld">
        <transform time="0"><scale value="0.3"/><rotate z="1" angle="-20"/><translate x="-1.2" y="0" z="5"/></transform>
        <transform time="1"><scale value="0.3"/><rotate z="1" angle="30"/><translate x="0.8" y="0.1" z="5"/></transform>
      </animation><ref id="black"/></shape>)";
  Film a = render_xml(scene_xml(grouped, 1.f)), b = render_xml(scene_xml(animated_scaled, 1.f));
  double total = 0, diff = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      total += 1.0 - a.mean({x, y}).g;
      diff += std::abs(a.mean({x, y}).g - b.mean({x, y}).g);
    }
  EXPECT_GT(total, 5.0);  // the cube is in view
  // Composing after interpolating vs interpolating the composition: equal for a uniform scale
  // up to rounding, so at most a few edge samples may differ.
  EXPECT_LT(diff, 0.02 * total);
}

bool same_bits(const Film& a, const Film& b) {
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (!(a.mean({x, y}) == b.mean({x, y}))) return false;
  return true;
}

// Nothing moves: an open shutter, an animation with equal keyframes, and a sphere whose
// center_close equals its centre all render the very bits of the static scene (the time sample
// comes from a dedicated dimension and the shapes stay in the static BVH).
TEST(MotionBlur, StaticScenesRenderTheSameBits) {
  const std::string still = R"(<shape type="sphere"><float name="radius" value="0.4"/>
      <point name="center" x="-0.2" y="0" z="5"/><ref id="black"/></shape>)";
  const Film reference = render_xml(scene_xml(still, 0.f));
  EXPECT_TRUE(same_bits(reference, render_xml(scene_xml(still, 1.f))));
  const std::string equal_keys = R"(<shape type="sphere"><float name="radius" value="0.4"/>
      <animation name="toWorld">
        <transform time="0"><translate x="-0.2" y="0" z="5"/></transform>
        <transform time="1"><translate x="-0.2" y="0" z="5"/></transform>
      </animation><ref id="black"/></shape>)";
  EXPECT_TRUE(same_bits(reference, render_xml(scene_xml(equal_keys, 1.f))));
  const std::string same_centre = R"(<shape type="sphere"><float name="radius" value="0.4"/>
      <point name="center" x="-0.2" y="0" z="5"/><point name="centerClose" x="-0.2" y="0" z="5"/><ref id="black"/></shape>)";
  EXPECT_TRUE(same_bits(reference, render_xml(scene_xml(same_centre, 1.f))));
  // A closed shutter (0/0) puts a moving sphere at its shutter-open centre, statically.
  const std::string at_open = R"(<shape type="sphere"><float name="radius" value="0.4"/>
      <point name="center" x="-0.2" y="0" z="5"/><point name="centerClose" x="1.5" y="0" z="5"/><ref id="black"/></shape>)";
  EXPECT_TRUE(same_bits(reference, render_xml(scene_xml(at_open, 0.f))));
  // ... and the test can tell images apart.
  EXPECT_FALSE(same_bits(reference, render_xml(scene_xml(at_open, 1.f))));
}

// Shadow rays see the scene at the path's time: a diffuse floor lit by a distant sun-like
// directional light, a sphere sliding above it, looked at from above. Each floor pixel is dark for
// the fraction of the shutter the sphere's shadow (the same disk, projected straight down) covers it.
TEST(MotionBlur, ShadowsMoveWithTheirCasters) {
  const std::string xml = R"(<scene version="0.6.0">
    <integrator type="path"><integer name="maxDepth" value="2"/></integrator>
    <sensor type="orthographic">
      <float name="shutterOpen" value="0"/><float name="shutterClose" value="1"/>
      <transform name="toWorld"><scale x="2" y="2"/></transform>
      <sampler type="independent"><integer name="sampleCount" value="2048"/></sampler>
      <film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="16"/>
        <rfilter type="box"><float name="radius" value="0.0001"/></rfilter></film>
    </sensor>
    <emitter type="directional"><vector name="direction" x="0" y="0" z="1"/><rgb name="irradiance" value="3.14159265"/></emitter>
    <shape type="rectangle"><transform name="toWorld"><scale value="10"/><rotate y="1" angle="180"/><translate z="9"/></transform>
      <bsdf type="diffuse"><rgb name="reflectance" value="1"/></bsdf></shape>
    <shape type="sphere"><float name="radius" value="0.4"/>
      <point name="center" x="-1.2" y="0" z="5"/><point name="centerClose" x="0.8" y="0" z="5"/>
      <bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf></shape>
  </scene>)";
  LoadOptions o;
  auto scene = load_scene(parse_scene_string(xml, "mem/motion_shadow.xml"), o).scene;
  RenderSettings rs;
  rs.spp = kSpp;
  rs.seed = 11;
  rs.threads = 2;
  const Film film = render(*scene, rs);
  // Seen pixels: the floor (value 1 where lit) unless the sphere itself is in front (value 0).
  // Light and view are both along +z, so shadow and sphere cover the same pixels at the same time:
  // a pixel is 1 - f either way, and a shadow ray at a wrong time would show up as extra light.
  expect_analytic_coverage(film);
}

}  // namespace
}  // namespace tessera
