// The baked sun/sky maps (light/sunsky.h, light/sunsky/sunsky_bake.h): radiance looked up against
// the model, the sun splat's irradiance, the directional sun, and importance sampling (chi-square).
#include "support/chi2.h"
#include "tessera/light/envmap.h"
#include "tessera/light/sunsky.h"
#include "tessera/light/sunsky/hosek_sky.h"
#include "tessera/light/sunsky/sun_spectrum.h"
#include "tessera/light/sunsky/sunsky_bake.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

namespace tessera {
namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr double kDeg = kPiD / 180.0;

SunskySettings settings(double sun_theta_deg, double sun_phi_deg) {
  SunskySettings s;
  s.sun = {sun_theta_deg * kDeg, sun_phi_deg * kDeg};
  return s;
}

TEST(SunskyMap, LookupMatchesTheModelAtTheCheckDirections) {
  const std::string path = test::shared_path("data/sunsky/check_sky_rgb.txt");
  TESSERA_REQUIRE_FILE(path);
  std::ifstream in(path);
  std::string line;
  double worst = 0, worst_exact = 0;
  int rows = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    double r[11];
    for (double& v : r) ss >> v;
    SunskySettings s = settings(r[4], 200.0);
    s.turbidity = r[0];
    s.albedo = Rgb(float(r[1]), float(r[2]), float(r[3]));
    s.with_sun = false;
    // Rotated to world, to exercise the frame: the lookup is in light space.
    s.to_world = Transform::rotate(normalize(Vec3(0.3f, 1.f, -0.2f)), 35.f);
    SunskyLights lights = make_sunsky_lights(s);
    ASSERT_TRUE(lights.map);
    EXPECT_FALSE(lights.directional);
    const Vec3 d = s.to_world.apply_vector(sunsky_direction(r[5] * kDeg, (200.0 + r[6]) * kDeg));
    Rgb l = lights.map->le_env(normalize(d));
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(l[c] - r[8 + c]) / r[8 + c]);
    ++rows;

    // At a texel the map holds the model itself: row 64 of 257 is theta = 45 deg, column 10.
    const auto& env = static_cast<const EnvmapLight&>(*lights.map);
    ASSERT_EQ(env.width(), 512);
    ASSERT_EQ(env.height(), 257);
    HosekSky sky(s.turbidity, s.albedo, s.sun.theta);
    Rgb exact = sky.eval_direction(kPiD * 0.25, 2.0 * kPiD * 10.5 / 512, s.sun.phi, 1.0);
    Rgb at_texel = env.lookup(Vec2(10.5f / 512.f, 64.f / 256.f));
    for (int c = 0; c < 3; ++c) worst_exact = std::max(worst_exact, double(std::abs(at_texel[c] - exact[c]) / exact[c]));
  }
  EXPECT_EQ(rows, 54);
  // Bilinear interpolation of a 0.7 deg grid: near the sun and the horizon the model is steep
  // (measured worst 7.4e-3 at 512 wide).
  std::printf("[ map ] worst relative error of the 512-wide map at the check directions: %.2e; at texels %.2e\n",
              worst, worst_exact);
  EXPECT_LT(worst, 1e-2);
  EXPECT_LT(worst_exact, 1e-5);
}

TEST(SunskyMap, TexelSolidAnglesSumToTheSphere) {
  for (int res : {8, 64, 512}) {
    const int h = sunsky_map_height(res);
    double sum = 0;
    for (int y = 0; y < h; ++y) sum += res * sunsky_texel_solid_angle(y, res, h);
    EXPECT_NEAR(sum, 4.0 * kPiD, 1e-9) << res;
  }
  EXPECT_EQ(sun_splat_sample_count(512, kSunHalfAngle), 716u);
  EXPECT_EQ(sun_splat_sample_count(64, kSunHalfAngle), 100u);
}

// Integral of le_env over a cap about `axis`, midpoint rule in (cos, azimuth) about it; `centroid`
// gets the green-radiance-weighted mean direction.
Rgb integrate_cap(const Light& light, Vec3 axis, double cap_angle, int n, Vec3& centroid) {
  Vec3 t = std::abs(axis.x) < 0.9f ? normalize(cross(axis, Vec3(1, 0, 0))) : normalize(cross(axis, Vec3(0, 1, 0)));
  Vec3 b = cross(axis, t);
  const double cmin = std::cos(cap_angle);
  double sum[3] = {0, 0, 0};
  Vec3 mean(0.f);
  for (int i = 0; i < n; ++i) {
    const double c = 1.0 - (1.0 - cmin) * (i + 0.5) / n, s = std::sqrt(1.0 - c * c);
    for (int j = 0; j < n; ++j) {
      const double a = 2.0 * kPiD * (j + 0.5) / n;
      Vec3 d = axis * float(c) + t * float(s * std::cos(a)) + b * float(s * std::sin(a));
      Rgb l = light.le_env(normalize(d));
      for (int k = 0; k < 3; ++k) sum[k] += l[k];
      mean += d * l.g;
    }
  }
  centroid = normalize(mean);
  const double cell = (1.0 - cmin) * 2.0 * kPiD / (double(n) * n);
  return Rgb(float(sum[0] * cell), float(sum[1] * cell), float(sum[2] * cell));
}

TEST(SunskyMap, SunSplatIntegratesToTheSunIrradiance) {
  for (double radius_scale : {1.0, 4.0, 25.0}) {
    SunskySettings s = settings(32.0, 100.0);
    s.with_sky = false;
    s.sun_radius_scale = radius_scale;
    s.sun_scale = 0.5f;
    s.to_world = Transform::rotate(Vec3(1, 0, 0), -90.f);  // Mitsuba 0.6 scenes often turn Y-up into Z-up
    const Rgb e = sunsky_sun_irradiance(s);
    const Rgb l = sun_radiance(s.turbidity, s.sun.theta).rgb * 0.5f;
    EXPECT_NEAR(e.g, l.g * 6.8683e-5f, 1e-4f * e.g);
    SunskyLights lights = make_sunsky_lights(s);
    ASSERT_TRUE(lights.map);
    ASSERT_FALSE(lights.directional);
    const auto& env = static_cast<const EnvmapLight&>(*lights.map);

    // Exactly, texel by texel (the bilinear hat solid angles), ...
    double exact[3] = {0, 0, 0};
    for (int y = 0; y < env.height(); ++y)
      for (int x = 0; x < env.width(); ++x) {
        Rgb v = env.lookup(Vec2((x + 0.5f) / env.width(), float(y) / (env.height() - 1)));
        for (int c = 0; c < 3; ++c) exact[c] += v[c] * sunsky_texel_solid_angle(y, env.width(), env.height());
      }
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(exact[c], e[c], 1e-5 * e[c]) << radius_scale;

    // ... and numerically over a cap around the sun that holds the whole blob.
    const Vec3 axis = sunsky_sun_direction_world(s);
    const double texel = 2.0 * kPiD / env.width();
    Vec3 centroid;
    Rgb cap = integrate_cap(*lights.map, axis, kSunHalfAngle * radius_scale + 3.0 * texel, 600, centroid);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(cap[c], e[c], 2e-3 * e[c]) << radius_scale << " ch " << c;
    // The blob is centred on the sun: its radiance-weighted mean direction is within a tenth of a texel.
    EXPECT_LT(std::acos(std::min(1.f, dot(centroid, axis))), 0.1 * texel) << radius_scale;
  }
}

TEST(SunskyMap, ZeroRadiusScaleGivesADirectionalSunOfTheSameIrradiance) {
  SunskySettings s = settings(50.0, 30.0);
  s.sun_radius_scale = 0.0;
  s.stretch = 1.5;  // the disk (and the directional sun) sits at zenith angle stretch * theta_s
  s.to_world = Transform::rotate(Vec3(0, 0, 1), 20.f);
  SunskyLights lights = make_sunsky_lights(s);
  ASSERT_TRUE(lights.map);
  ASSERT_TRUE(lights.directional);
  EXPECT_TRUE(lights.directional->is_delta());
  LightSample ls;
  ASSERT_TRUE(lights.directional->sample_li(Vec3(1.f, 2.f, 3.f), Vec2(0.5f, 0.5f), ls));
  Rgb e = sun_radiance(3.0, 50 * kDeg).rgb * float(sun_solid_angle());
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(ls.li[c], e[c], 1e-4f * e[c]);
  Vec3 expected = normalize(s.to_world.apply_vector(sunsky_direction(75 * kDeg, 30 * kDeg)));
  EXPECT_GT(dot(ls.wi, expected), 1.f - 1e-6f);
  // The sky map carries no sun: radiance towards the sun is sky-sized.
  EXPECT_LT(lights.map->le_env(expected).g, 10.f);

  s.with_sky = false;  // `sun` alone with radius 0: only the directional light
  SunskyLights sun_only = make_sunsky_lights(s);
  EXPECT_FALSE(sun_only.map);
  EXPECT_TRUE(sun_only.directional);
}

test::Chi2Sample sample_of(const Light& light, Vec2 u) {
  LightSample ls;
  if (!light.sample_li(Vec3(0.f), u, ls)) return {Vec3(), 0.f, false};
  return {ls.wi, ls.pdf};
}

TEST(SunskyMap, ImportanceSamplingMatchesPdfEnv) {
  struct Case {
    const char* name;
    bool sun;
    double radius_scale;
  };
  const Case cases[] = {{"sky", false, 1.0}, {"sunsky, sunRadiusScale 30", true, 30.0}};
  for (const Case& c : cases) {
    SunskySettings s = settings(60.0, 120.0);
    s.resolution = 128;
    s.with_sun = c.sun;
    s.sun_radius_scale = c.radius_scale;
    s.to_world = Transform::rotate(normalize(Vec3(1, 0.5f, 0)), 30.f);
    SunskyLights lights = make_sunsky_lights(s);
    ASSERT_TRUE(lights.map);
    const Light& light = *lights.map;
    test::Chi2Options o;
    o.name = c.name;
    o.test_count = 2;
    o.integration_resolution = 12;
    auto r = test::chi2_test([&](Vec2 u) { return sample_of(light, u); },
                             [&](Vec3 w) { return double(light.pdf_env(w)); }, o);
    EXPECT_TRUE(r.passed) << r.message;
    std::printf("[ chi2 ] %s: statistic %.1f, dof %d, p %.3f\n", c.name, r.statistic, r.dof, r.p_value);
    if (c.sun) {
      // The peak is resolvable: most samples land in the sun.
      const Vec3 axis = sunsky_sun_direction_world(s);
      int in_sun = 0;
      for (int i = 0; i < 1000; ++i) {
        test::Chi2Sample smp = sample_of(light, Vec2((i + 0.5f) / 1000.f, float((i * 0.618034) - std::floor(i * 0.618034))));
        if (smp.valid && dot(smp.wi, axis) > std::cos(kSunHalfAngle * c.radius_scale + 0.1)) ++in_sun;
      }
      EXPECT_GT(in_sun, 500);
    }
  }
}

}  // namespace
}  // namespace tessera
