// `sunsky`, `sky` and `sun` from scene XML: parameters, the two-light sunsky, errors with file and
// line; and a diffuse plane rendered under a sunsky against its analytic brightness.
#include "render/scene_builders.h"
#include "tessera/light/envmap.h"
#include "tessera/light/sunsky.h"
#include "tessera/light/sunsky/hosek_sky.h"
#include "tessera/light/sunsky/sun_spectrum.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr double kDeg = kPiD / 180.0;

struct Loaded {
  SceneDesc desc;
  Scene scene;
  std::unique_ptr<Light> light;  // what the factory returned; extra lights are in scene.lights
};

std::unique_ptr<Loaded> load(const std::string& body) {
  auto l = std::make_unique<Loaded>();
  l->desc = parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/sunsky.xml");
  LoadContext ctx(l->desc, LoadOptions{}, l->scene);
  auto node = l->desc.root->children_with_tag("emitter").at(0);
  l->light = find_light_factory(node->type)(*node, ctx);
  return l;
}

TEST(SunskyFactory, SunDirectionScalesAndResolution) {
  auto l = load(R"(<emitter type="sunsky"><vector name="sunDirection" x="0" y="1" z="1"/>
      <float name="turbidity" value="4"/><float name="skyScale" value="2"/><float name="sunScale" value="0.5"/>
      <integer name="resolution" value="64"/><rgb name="albedo" value="0.1 0.2 0.3"/></emitter>)");
  ASSERT_TRUE(l->light);
  EXPECT_TRUE(l->scene.lights.empty());  // sun in the map: one light
  const auto& env = static_cast<const EnvmapLight&>(*l->light);
  EXPECT_EQ(env.width(), 64);
  EXPECT_EQ(env.height(), 33);
  // The sky at the zenith, sun 45 deg away: skyScale times the model.
  HosekSky sky(4.0, Rgb(0.1f, 0.2f, 0.3f), 45 * kDeg);
  Rgb zenith = sky.eval(0.0, 45 * kDeg) * 2.f;
  EXPECT_NEAR(env.le_env(Vec3(0, 1, 0)).b, zenith.b, 1e-5f * zenith.b);
  // The sun blob is where sunDirection points, sunScale times the disk.
  const Vec3 sun = normalize(Vec3(0, 1, 1));
  EXPECT_GT(env.le_env(sun).g, 100.f * env.le_env(-sun).g);
}

TEST(SunskyFactory, ZeroSunRadiusScaleAddsADirectionalLight) {
  auto l = load(R"(<emitter type="sunsky"><float name="sunRadiusScale" value="0"/>
      <float name="scale" value="3"/><integer name="resolution" value="32"/></emitter>)");
  ASSERT_TRUE(l->light);
  EXPECT_TRUE(l->light->is_infinite());
  ASSERT_EQ(l->scene.lights.size(), 1u);
  const Light& sun = *l->scene.lights[0];
  EXPECT_TRUE(sun.is_delta());
  LightSample ls;
  ASSERT_TRUE(sun.sample_li(Vec3(0.f), Vec2(0.5f, 0.5f), ls));
  // Default time and place: theta 43.921 deg, phi 265.752 deg; `scale` is the default sunScale.
  SunskySettings s;
  s.sun = solar_position(SunTimeAndPlace{});
  s.sun_scale = 3.f;
  Rgb e = sunsky_sun_irradiance(s);
  EXPECT_NEAR(ls.li.r, e.r, 1e-4f * e.r);
  EXPECT_NEAR(ls.wi.x, -0.6918f, 1e-4f);
  EXPECT_NEAR(ls.wi.y, 0.7203f, 1e-4f);
}

TEST(SunskyFactory, SkyAndSunAlone) {
  auto sky = load(R"(<emitter type="sky"><float name="hour" value="12"/><integer name="resolution" value="32"/>
      <float name="scale" value="2"/></emitter>)");
  ASSERT_TRUE(sky->light);
  EXPECT_TRUE(sky->scene.lights.empty());
  SunAngles noon = solar_position(SunTimeAndPlace{2010, 7, 10, 12});
  Rgb zenith = HosekSky(3.0, Rgb(0.2f), noon.theta).eval(0.0, noon.theta) * 2.f;
  EXPECT_NEAR(sky->light->le_env(Vec3(0, 1, 0)).g, zenith.g, 1e-5f * zenith.g);
  // No sun in a sky: towards the sun the map is sky-bright only.
  EXPECT_LT(sky->light->le_env(sunsky_direction(noon.theta, noon.phi)).g, 10.f);

  auto sun = load(R"(<emitter type="sun"><integer name="resolution" value="64"/></emitter>)");
  ASSERT_TRUE(sun->light);
  EXPECT_TRUE(sun->light->is_infinite());
  EXPECT_EQ(sun->light->le_env(Vec3(0, 1, 0)), Rgb(0.f));  // no sky
  auto delta = load(R"(<emitter type="sun"><float name="sunRadiusScale" value="0"/></emitter>)");
  ASSERT_TRUE(delta->light);
  EXPECT_TRUE(delta->light->is_delta());
  EXPECT_TRUE(delta->scene.lights.empty());
}

TEST(SunskyFactory, ErrorsNameFileAndLine) {
  auto error = [](const std::string& body) { return test::scene_error_of([&] { load(body); }); };
  std::string t = error("<emitter type=\"sunsky\">\n<float name=\"turbidity\" value=\"11\"/></emitter>");
  EXPECT_NE(t.find("mem/sunsky.xml:3"), std::string::npos) << t;
  EXPECT_NE(t.find("turbidity"), std::string::npos) << t;
  std::string low = error("<emitter type=\"sky\"><float name=\"turbidity\" value=\"0.5\"/></emitter>");
  EXPECT_NE(low.find("turbidity"), std::string::npos) << low;
  std::string both = error(
      "<emitter type=\"sunsky\"><vector name=\"sunDirection\" x=\"0\" y=\"1\" z=\"0\"/>\n"
      "<float name=\"latitude\" value=\"10\"/></emitter>");
  EXPECT_NE(both.find("mem/sunsky.xml:3"), std::string::npos) << both;
  EXPECT_NE(both.find("sunDirection"), std::string::npos) << both;
  std::string night = error("<emitter type=\"sunsky\"><float name=\"hour\" value=\"23\"/></emitter>");
  EXPECT_NE(night.find("below the horizon"), std::string::npos) << night;
  std::string down = error("<emitter type=\"sun\"><vector name=\"sunDirection\" x=\"0\" y=\"-1\" z=\"0.2\"/></emitter>");
  EXPECT_NE(down.find("below the horizon"), std::string::npos) << down;
  std::string albedo = error("<emitter type=\"sky\"><float name=\"albedo\" value=\"1.5\"/></emitter>");
  EXPECT_NE(albedo.find("albedo"), std::string::npos) << albedo;
  std::string stretch = error("<emitter type=\"sunsky\"><float name=\"stretch\" value=\"3\"/></emitter>");
  EXPECT_NE(stretch.find("stretch"), std::string::npos) << stretch;
}

// Irradiance on an upward (+y) plane from a light's le_env over the upper hemisphere (midpoint in
// cos theta and phi).
double sky_irradiance_luminance(const std::function<Rgb(Vec3)>& le, int n) {
  double sum = 0;
  for (int i = 0; i < n; ++i) {
    const double c = (i + 0.5) / n, s = std::sqrt(1.0 - c * c);
    for (int j = 0; j < 2 * n; ++j) {
      const double phi = kPiD * (j + 0.5) / n;
      sum += le(Vec3(float(s * std::sin(phi)), float(c), float(-s * std::cos(phi)))).luminance() * c;
    }
  }
  return sum * (1.0 / n) * (kPiD / n);
}

TEST(SunskyRender, DiffusePlaneMatchesTheAnalyticIrradiance) {
  SunskySettings s;
  s.sun = {40 * kDeg, 150 * kDeg};
  s.resolution = 256;
  s.sun_radius_scale = 4.0;  // a resolvable disk: still E cos(theta_s) to 1e-5
  SunskyLights lights = make_sunsky_lights(s);
  ASSERT_TRUE(lights.map);

  // Analytic: the sky integrated numerically from the model (and from the map, to bound the bake
  // error), plus the sun's E cos(theta_s).
  HosekSky sky(s.turbidity, s.albedo, s.sun.theta);
  const double e_sky_model = sky_irradiance_luminance([&](Vec3 d) {
    SunAngles a = sun_angles_from_direction(d);
    return sky.eval_direction(a.theta, a.phi, s.sun.phi, 1.0);
  }, 400);
  SunskySettings sky_only = s;
  sky_only.with_sun = false;
  SunskyLights sky_map = make_sunsky_lights(sky_only);
  const double e_sky_map = sky_irradiance_luminance([&](Vec3 d) { return sky_map.map->le_env(d); }, 400);
  EXPECT_NEAR(e_sky_map, e_sky_model, 2e-3 * e_sky_model);
  const double e_sun = double(sunsky_sun_irradiance(s).luminance()) * std::cos(s.sun.theta);
  const float albedo = 0.5f;
  const double expected = albedo / kPiD * (e_sky_model + e_sun);

  auto scene = std::make_unique<Scene>();
  auto plane = std::make_shared<MeshData>();
  plane->positions = {{-100.f, 0.f, -100.f}, {100.f, 0.f, -100.f}, {100.f, 0.f, 100.f}, {-100.f, 0.f, 100.f}};
  plane->indices = {0, 2, 1, 0, 3, 2};  // normal +y
  scene->shapes.push_back(std::make_unique<TriangleMeshShape>(plane, false, true));
  scene->shapes.back()->bsdf = test::add_diffuse(*scene, Rgb(albedo));
  scene->lights.push_back(std::move(lights.map));
  auto xf = Transform::look_at({0.f, 5.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 1.f});
  scene->camera = make_perspective_camera(*xf, 40.f, 16, 16, 1e-3f, 1e4f);
  scene->film.width = scene->film.height = 16;
  scene->integrator.max_depth = 2;
  scene->finalize();
  RenderSettings rs;
  rs.spp = 64;
  rs.seed = 7;
  rs.threads = 2;
  rs.tile_size = 16;
  RenderStats stats;
  Film film = render(*scene, rs, {}, &stats);
  EXPECT_EQ(stats.counters.nonfinite, 0u);
  double sum = 0, sum_var = 0;
  int n = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      Rgb m = film.mean({x, y});
      ASSERT_TRUE(m.is_finite());
      sum += m.luminance();
      sum_var += film.sample_variance({x, y}).luminance() / double(film.pixel({x, y}).count);
      ++n;
    }
  const double mean = sum / n, se = std::sqrt(sum_var) / n;
  std::printf("[ render ] plane luminance %.6f +- %.6f, analytic %.6f (sky %.5f, map %.5f, sun %.5f)\n", mean, se,
              expected, e_sky_model, e_sky_map, e_sun);
  EXPECT_NEAR(mean, expected, 4.0 * se + 2e-3 * expected);
}

}  // namespace
}  // namespace tessera
