// The `envmap` emitter: Mitsuba's orientation, importance sampling (chi-square), pdf/radiance
// consistency for MIS, and irradiance against numeric integration.
#include "support/chi2.h"
#include "tessera/core/hash.h"
#include "tessera/core/transform.h"
#include "tessera/image/image.h"
#include "tessera/light/envmap.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace tessera {
namespace {

struct Texel {
  int x, y;
  Rgb value;
};

Image make_map(int w, int h, Rgb background, std::initializer_list<Texel> texels = {}) {
  Image img(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.set_rgb(x, y, background);
  for (const auto& t : texels) img.set_rgb(t.x, t.y, t.value);
  return img;
}

void expect_vec_near(Vec3 a, Vec3 b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

float angle_between(Vec3 a, Vec3 b) { return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.f, 1.f)); }

test::Chi2Sample sample_of(const Light& light, Vec2 u) {
  LightSample ls;
  if (!light.sample_li(Vec3(0.f), u, ls)) return {Vec3(), 0.f, false};
  return {ls.wi, ls.pdf};
}

TEST(EnvmapOrientation, UvLandmarksFollowMitsuba) {
  expect_vec_near(envmap_uv_to_direction({0.5f, 0.5f}), {0, 0, 1}, 1e-6f);    // image centre: +z
  expect_vec_near(envmap_uv_to_direction({0.25f, 0.5f}), {1, 0, 0}, 1e-6f);   // a quarter in: +x
  expect_vec_near(envmap_uv_to_direction({0.f, 0.5f}), {0, 0, -1}, 1e-6f);    // left edge: -z
  expect_vec_near(envmap_uv_to_direction({0.75f, 0.5f}), {-1, 0, 0}, 1e-6f);
  expect_vec_near(envmap_uv_to_direction({0.3f, 0.f}), {0, 1, 0}, 1e-6f);     // top row: +y
  expect_vec_near(envmap_uv_to_direction({0.3f, 1.f}), {0, -1, 0}, 1e-6f);
  Pcg32 rng(5);
  for (int i = 0; i < 1000; ++i) {
    Vec2 uv(rng.next_float(), 0.01f + 0.98f * rng.next_float());
    Vec2 back = envmap_direction_to_uv(envmap_uv_to_direction(uv));
    EXPECT_NEAR(back.x, uv.x, 1e-5f);
    EXPECT_NEAR(back.y, uv.y, 1e-5f);
  }
}

TEST(EnvmapOrientation, BrightTexelAppearsWhereMitsubaPutsIt) {
  // W = 4, H = 3: column 1 is centred on u = 1.5/4 (phi = 135 deg), row 1 on v = 1/2 (the equator),
  // so Mitsuba 3 shows the texel in direction (sin 135, 0, -cos 135).
  EnvmapLight light(make_map(4, 3, Rgb(0.f), {{1, 1, Rgb(10.f, 20.f, 30.f)}}), 1.f, Transform());
  const Vec3 d(std::sqrt(0.5f), 0.f, std::sqrt(0.5f));
  Rgb peak = light.le_env(d);
  EXPECT_NEAR(peak.r, 10.f, 1e-3f);
  EXPECT_NEAR(peak.b, 30.f, 1e-3f);
  EXPECT_EQ(light.le_env(-d), Rgb(0.f));
  EXPECT_EQ(light.le_env(Vec3(0, 1, 0)), Rgb(0.f));
  // Half-way (in u) to the next column: bilinear.
  Rgb half = light.le_env(envmap_uv_to_direction({2.f / 4.f, 0.5f}));
  EXPECT_NEAR(half.r, 5.f, 1e-3f);

  // `scale` multiplies.
  EnvmapLight scaled(make_map(4, 3, Rgb(0.f), {{1, 1, Rgb(10.f)}}), 0.5f, Transform());
  EXPECT_NEAR(scaled.le_env(d).g, 5.f, 1e-3f);
}

TEST(EnvmapOrientation, PeakOfAFinerMapIsAtThePredictedDirection) {
  const int w = 64, h = 33, tx = 40, ty = 10;
  EnvmapLight light(make_map(w, h, Rgb(0.1f), {{tx, ty, Rgb(100.f)}}), 1.f, Transform());
  Vec3 predicted = envmap_uv_to_direction({(tx + 0.5f) / w, float(ty) / (h - 1)});
  // Brute-force search for the brightest direction.
  Vec3 best;
  float best_value = -1;
  for (int i = 0; i < 400; ++i)
    for (int j = 0; j < 800; ++j) {
      float c = 1.f - 2.f * (i + 0.5f) / 400.f, s = std::sqrt(1.f - c * c), phi = 2.f * kPi * (j + 0.5f) / 800.f;
      Vec3 dir(s * std::cos(phi), c, s * std::sin(phi));
      float v = light.le_env(dir).g;
      if (v > best_value) best_value = v, best = dir;
    }
  EXPECT_LT(angle_between(best, predicted), 0.5f * kPi / (h - 1));
  EXPECT_NEAR(light.le_env(predicted).g, 100.f, 1e-2f);
}

TEST(EnvmapOrientation, ToWorldRotatesTheMap) {
  const Vec3 d(std::sqrt(0.5f), 0.f, std::sqrt(0.5f));  // where texel (1,1) of a 4x3 map lies
  Transform rot_y = Transform::rotate({0, 1, 0}, 90.f);
  EnvmapLight light(make_map(4, 3, Rgb(0.f), {{1, 1, Rgb(10.f)}}), 1.f, rot_y);
  // A right-handed 90 degree turn about +y takes (x, 0, z) to (z, 0, -x).
  Vec3 moved(std::sqrt(0.5f), 0.f, -std::sqrt(0.5f));
  expect_vec_near(rot_y.apply_vector(d), moved, 1e-5f);
  EXPECT_NEAR(light.le_env(moved).r, 10.f, 1e-3f);
  EXPECT_EQ(light.le_env(d), Rgb(0.f));

  // Tilting +y (the top row) towards +z... a 90 degree turn about +x takes +y to +z.
  Image top = make_map(8, 5, Rgb(0.f));
  for (int x = 0; x < 8; ++x) top.set_rgb(x, 0, Rgb(5.f));
  EnvmapLight tilted(top, 1.f, Transform::rotate({1, 0, 0}, 90.f));
  EXPECT_NEAR(tilted.le_env(Vec3(0, 0, 1)).r, 5.f, 1e-3f);
  EXPECT_EQ(tilted.le_env(Vec3(0, 1, 0)), Rgb(0.f));
  // Sampling follows the rotation too: every sample lies near +z.
  Pcg32 rng(3);
  for (int i = 0; i < 1000; ++i) {
    LightSample ls;
    ASSERT_TRUE(tilted.sample_li(Vec3(0.f), {rng.next_float(), rng.next_float()}, ls));
    EXPECT_GT(ls.wi.z, std::cos(kPi / 4.f) - 1e-4f);
  }
}

// For MIS: the pdf a sample reports is pdf_env() of its direction, and li is le_env() of it. A
// sample with its radiance deferred is the same sample, and deferred_li() the same radiance.
void check_sample_consistency(const EnvmapLight& light, int n, uint64_t seed) {
  Pcg32 rng(seed);
  int pdf_mismatch = 0;
  for (int i = 0; i < n; ++i) {
    LightSample ls, deferred;
    deferred.defer_li = true;
    Vec3 ref(1.f, 2.f, 3.f);
    const Vec2 u(rng.next_float(), rng.next_float());
    ASSERT_TRUE(light.sample_li(ref, u, ls));
    ASSERT_TRUE(light.sample_li(ref, u, deferred));
    ASSERT_FALSE(ls.li_deferred);
    ASSERT_TRUE(deferred.li_deferred);
    ASSERT_EQ(deferred.li, Rgb(0.f)) << "a deferred sample does not look its radiance up";
    ASSERT_EQ(light.deferred_li(deferred), ls.li) << i;
    ASSERT_EQ(deferred.wi, ls.wi);
    ASSERT_EQ(deferred.pdf, ls.pdf);
    ASSERT_GT(ls.pdf, 0.f);
    ASSERT_TRUE(std::isfinite(ls.pdf));
    ASSERT_NEAR(length(ls.wi), 1.f, 1e-5f);
    EXPECT_FALSE(ls.delta);
    EXPECT_EQ(ls.dist, kInfinity);
    EXPECT_GT(dot(ls.p_light - ref, ls.wi), 0.f);
    float pdf = light.pdf_env(ls.wi);
    // A sample within rounding of a cell edge may map back to the neighbouring cell.
    if (std::abs(pdf - ls.pdf) > 1e-3f * ls.pdf) ++pdf_mismatch;
    Rgb le = light.le_env(ls.wi);
    // A float direction pins (u, v) down to ~1e-7 only; next to a texel 1000x brighter than its
    // neighbours (a sun), or near a pole where u is ill-conditioned, that moves the bilinear value
    // visibly. Allow what a 1e-6 nudge of the direction changes, plus 0.2%.
    float spread = 0.f;
    for (int axis = 0; axis < 3; ++axis)
      for (float sign : {-1.f, 1.f}) {
        Vec3 nudged = ls.wi;
        nudged[axis] += sign * 1e-6f;
        spread = std::max(spread, (light.le_env(normalize(nudged)) - le).max_value());
        spread = std::max(spread, (le - light.le_env(normalize(nudged))).max_value());
      }
    float tol = 2e-3f * std::max(ls.li.max_value(), 1e-3f) + spread;
    ASSERT_NEAR(le.r, ls.li.r, tol) << i;
    ASSERT_NEAR(le.g, ls.li.g, tol) << i;
    ASSERT_NEAR(le.b, ls.li.b, tol) << i;
  }
  EXPECT_LE(pdf_mismatch, n / 2000) << pdf_mismatch << " of " << n << " sample pdfs differ from pdf_env()";
}

std::string shared_envmap(const char* name) { return test::shared_path(std::string("scenes/envmaps/") + name); }

TEST(EnvmapSampling, ReportedPdfAndRadianceMatchPdfEnvAndLeEnv) {
  check_sample_consistency(EnvmapLight(make_map(16, 9, Rgb(0.05f), {{3, 4, Rgb(5000.f)}}), 1.f, Transform()),
                           100000, 1);
  check_sample_consistency(EnvmapLight(make_map(16, 9, Rgb(0.2f, 0.5f, 1.f), {{15, 0, Rgb(50.f)}}), 2.f,
                                       Transform::rotate({1, 1, 0}, 37.f)),
                           100000, 2);
  std::string path = shared_envmap("mitsuba_tests_envmap.exr");
  TESSERA_REQUIRE_FILE(path);
  check_sample_consistency(EnvmapLight(read_image(path), 1.f, Transform::rotate({0, 0, 1}, -20.f)), 100000, 3);
}

TEST(EnvmapSampling, ChiSquareSyntheticMapWithOneVeryBrightTexel) {
  EnvmapLight light(make_map(16, 9, Rgb(0.05f), {{5, 2, Rgb(5000.f)}}), 1.f, Transform());
  test::Chi2Options o;
  o.name = "envmap with a bright texel";
  o.test_count = 3;
  o.integration_resolution = 32;
  auto r = test::chi2_test([&](Vec2 u) { return sample_of(light, u); },
                           [&](Vec3 w) { return double(light.pdf_env(w)); }, o);
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2);
}

TEST(EnvmapSampling, ChiSquareRealMap) {
  std::string path = shared_envmap("mitsuba_tests_envmap.exr");
  TESSERA_REQUIRE_FILE(path);
  EnvmapLight light(read_image(path), 1.f, Transform::rotate({1, 0, 0}, 30.f));
  test::Chi2Options o;
  o.name = "mitsuba_tests_envmap.exr";
  o.test_count = 3;
  o.cos_theta_bins = 20;
  o.phi_bins = 40;
  o.integration_resolution = 64;  // the pdf has a step at every one of the 512x255 cells
  auto r = test::chi2_test([&](Vec2 u) { return sample_of(light, u); },
                           [&](Vec3 w) { return double(light.pdf_env(w)); }, o);
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2);
}

TEST(EnvmapSampling, ChiSquareDetectsAWrongPdf) {
  // The same light checked against a pdf that ignores the map (uniform): must fail, or the two
  // tests above prove nothing.
  EnvmapLight light(make_map(16, 9, Rgb(0.05f), {{5, 2, Rgb(50.f)}}), 1.f, Transform());
  test::Chi2Options o;
  o.name = "envmap vs uniform pdf";
  o.sample_count = 200000;
  auto r = test::chi2_test([&](Vec2 u) { return sample_of(light, u); }, [](Vec3) { return double(kInv4Pi); }, o);
  EXPECT_FALSE(r.passed) << r.message;
}

// Irradiance on a plane facing +y (world) by integrating the map numerically over the upper
// hemisphere: midpoint rule on a fine (cos theta, phi) grid about +y, in world space, so it knows
// nothing about the light's cells or sampling.
Rgb irradiance_quadrature(const Light& light, int n_cos, int n_phi) {
  double sum[3] = {0, 0, 0};
  double d_omega = (1.0 / n_cos) * (2.0 * M_PI / n_phi);
  for (int i = 0; i < n_cos; ++i) {
    double c = (i + 0.5) / n_cos, s = std::sqrt(1.0 - c * c);
    for (int j = 0; j < n_phi; ++j) {
      double phi = 2.0 * M_PI * (j + 0.5) / n_phi;
      Rgb l = light.le_env(Vec3(float(s * std::cos(phi)), float(c), float(s * std::sin(phi))));
      for (int k = 0; k < 3; ++k) sum[k] += double(l[k]) * c * d_omega;
    }
  }
  return Rgb(float(sum[0]), float(sum[1]), float(sum[2]));
}

void check_irradiance(const EnvmapLight& light, int n_cos, int n_phi, uint64_t seed) {
  Rgb expected = irradiance_quadrature(light, n_cos, n_phi);
  const int n = 1000000;
  double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
  Pcg32 rng(seed);
  for (int i = 0; i < n; ++i) {
    LightSample ls;
    if (!light.sample_li(Vec3(0.f), {rng.next_float(), rng.next_float()}, ls)) continue;
    double w = std::max(0.0, double(ls.wi.y)) / ls.pdf;
    for (int k = 0; k < 3; ++k) {
      double f = double(ls.li[k]) * w;
      sum[k] += f;
      sum2[k] += f * f;
    }
  }
  for (int k = 0; k < 3; ++k) {
    double mean = sum[k] / n, var = std::max(0.0, sum2[k] / n - mean * mean);
    double stderr_ = std::sqrt(var / n);
    // 5 sigma of Monte Carlo noise plus 0.2% for the quadrature.
    EXPECT_NEAR(mean, expected[k], 5.0 * stderr_ + 2e-3 * expected[k]) << "channel " << k;
    EXPECT_GT(expected[k], 0.f);
  }
}

TEST(EnvmapSampling, IrradianceMatchesNumericIntegration) {
  check_irradiance(EnvmapLight(make_map(16, 9, Rgb(0.05f, 0.1f, 0.2f), {{5, 2, Rgb(500.f)}}), 1.f, Transform()),
                   1024, 2048, 7);
  std::string path = shared_envmap("mitsuba_tests_envmap.exr");
  TESSERA_REQUIRE_FILE(path);
  Image map = read_image(path);
  check_irradiance(EnvmapLight(map, 1.f, Transform()), 1024, 2048, 8);
  check_irradiance(EnvmapLight(map, 3.f, Transform::rotate({1, 0, 0}, 30.f)), 1024, 2048, 9);
}

TEST(EnvmapLight, PowerIsPiR2TimesIntegratedLuminance) {
  EnvmapLight light(make_map(8, 5, Rgb(2.f)), 1.f, Transform());
  EXPECT_NEAR(light.power(), kPi * 4.f * kPi * 2.f, 1e-3f);  // R = 1 before preprocess
  Bounds3 b;
  b.extend(Vec3(-1, -2, -2));
  b.extend(Vec3(1, 2, 2));  // radius 3
  light.preprocess(b);
  EXPECT_NEAR(light.power(), kPi * 9.f * 4.f * kPi * 2.f, 1e-2f);
  EXPECT_TRUE(light.is_infinite());
  EXPECT_FALSE(light.is_delta());
}

TEST(EnvmapLight, BlackMapIsHarmless) {
  EnvmapLight light(make_map(4, 3, Rgb(0.f)), 1.f, Transform());
  EXPECT_EQ(light.power(), 0.f);
  Pcg32 rng(1);
  for (int i = 0; i < 100; ++i) {
    LightSample ls;
    if (light.sample_li(Vec3(0.f), {rng.next_float(), rng.next_float()}, ls)) {
      EXPECT_EQ(ls.li, Rgb(0.f));
      EXPECT_TRUE(std::isfinite(ls.pdf));
    }
    EXPECT_TRUE(std::isfinite(light.pdf_env(ls.wi)));
  }
}

TEST(EnvmapLight, EverySharedEnvmapBuildsAndSamplesConsistently) {
  std::filesystem::path dir = test::shared_path("scenes/envmaps");
  TESSERA_REQUIRE_FILE(dir.string());
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    if (ext != ".exr" && ext != ".hdr") continue;
    SCOPED_TRACE(entry.path().filename().string());
    EnvmapLight light(read_image(entry.path().string()), 1.f, Transform());
    EXPECT_GT(light.power(), 0.f);
    check_sample_consistency(light, 2000, uint64_t(n));
    ++n;
  }
  EXPECT_EQ(n, 7);
}

}  // namespace
}  // namespace tessera
