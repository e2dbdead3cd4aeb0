// Emission sampling (Light::sample_le) as an estimator: the mean emitted weight
// le * cos / (pdf_pos * pdf_dir) of its samples is the power the light emits, computed here without
// its sampler (pi A L, 4 pi I, the spot's profile integral, E pi R^2, the radiance integrated over
// the sphere times pi R^2). And lights that emit nothing fail cleanly, with no NaN.
#include "light/emission_fixtures.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using test::EmitterCase;
using test::EmitterKind;

/// Per channel: mean and standard error of the emitted weight over n samples (failed samples
/// count as zero: they emit nothing).
struct PowerEstimate {
  double mean[3] = {0, 0, 0}, std_error[3] = {0, 0, 0};
};

PowerEstimate estimate_power(const Light& light, bool area, int n) {
  double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
  Pcg32 rng(17);
  for (int k = 0; k < n; ++k) {
    LightEmission e;
    if (!light.sample_le({rng.next_float(), rng.next_float()}, {rng.next_float(), rng.next_float()}, e)) continue;
    const double cos = area ? std::abs(double(dot(e.n, e.dir))) : 1.0;
    for (int c = 0; c < 3; ++c) {
      const double w = double(e.le[c]) * cos / (double(e.pdf_pos) * double(e.pdf_dir));
      sum[c] += w;
      sum2[c] += w * w;
    }
  }
  PowerEstimate out;
  for (int c = 0; c < 3; ++c) {
    out.mean[c] = sum[c] / n;
    const double var = std::max(0.0, sum2[c] / n - out.mean[c] * out.mean[c]);
    out.std_error[c] = std::sqrt(var / n);
  }
  return out;
}

TEST(EmissionPower, MeanEmittedWeightIsThePower) {
  test::EmitterShapes shapes;
  for (const EmitterCase& c : test::make_emitter_cases(shapes)) {
    const PowerEstimate p = estimate_power(*c.light, c.kind == EmitterKind::Area, 400000);
    for (int ch = 0; ch < 3; ++ch) {
      const double expected = double(c.power[ch]);
      ASSERT_GT(expected, 0.0) << c.name;
      // 4 standard errors of the estimate, plus float rounding of the weights (and of the numeric
      // integral the map powers come from).
      const double tol = 4.0 * p.std_error[ch] + 1e-3 * expected;
      EXPECT_NEAR(p.mean[ch], expected, tol) << c.name << " channel " << ch << ", standard error " << p.std_error[ch];
    }
    std::printf("[ power ] %-18s expected %.5g, estimated %.5g +- %.2g (green)\n", c.name.c_str(),
                double(c.power[1]), p.mean[1], p.std_error[1]);
  }
}

/// Fails cleanly: false, and pdf_le gives finite non-negative densities.
void expect_no_emission(const Light& light, const char* name) {
  Pcg32 rng(1);
  for (int k = 0; k < 200; ++k) {
    LightEmission e;
    EXPECT_FALSE(light.sample_le({rng.next_float(), rng.next_float()}, {rng.next_float(), rng.next_float()}, e))
        << name;
  }
  float pdf_pos = -1.f, pdf_dir = -1.f;
  light.pdf_le(Vec3(0.f), Vec3(0.f, 0.f, 1.f), normalize(Vec3(0.3f, 0.4f, 0.5f)), pdf_pos, pdf_dir);
  EXPECT_TRUE(std::isfinite(pdf_pos) && pdf_pos >= 0.f) << name << ": pdf_pos " << pdf_pos;
  EXPECT_TRUE(std::isfinite(pdf_dir) && pdf_dir >= 0.f) << name << ": pdf_dir " << pdf_dir;
}

TEST(EmissionDegenerate, ZeroPowerLightsEmitNothing) {
  const Rgb black(0.f);
  SphereShape sphere(Vec3(0.f), 1.f, false);
  TriangleMeshShape quad(test::bent_quad(), false, true);
  const Transform aim = *Transform::look_at({0.f, 0.f, 0.f}, {0.f, 0.f, 1.f}, {0.f, 1.f, 0.f});
  std::vector<std::pair<const char*, std::unique_ptr<Light>>> lights;
  lights.emplace_back("area sphere", make_area_light(sphere, black));
  lights.emplace_back("area mesh", make_area_light(quad, black));
  lights.emplace_back("triangle", make_triangle_light(quad, 0, black));
  lights.emplace_back("point", make_point_light(Vec3(0.f), black));
  lights.emplace_back("spot", make_spot_light(aim, black, 30.f, 20.f));
  lights.emplace_back("directional", make_directional_light(Vec3(0.f, 0.f, 1.f), black));
  lights.emplace_back("constant", std::make_unique<ConstantLight>(black));
  Image map(8, 5, 3);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 8; ++x) map.set_rgb(x, y, black);
  lights.emplace_back("envmap", std::make_unique<EnvmapLight>(map, 1.f, Transform()));
  for (auto& [name, light] : lights) {
    light->preprocess(test::emission_scene_bounds());
    expect_no_emission(*light, name);
  }
}

TEST(EmissionDegenerate, ZeroAreaShapesEmitNothing) {
  const Rgb l(1.f);
  SphereShape point_sphere(Vec3(1.f, 2.f, 3.f), 1e-30f, false);  // its area underflows to 0
  auto line = std::make_shared<MeshData>();  // collinear vertices: a triangle of zero area
  line->positions = {{0.f, 0.f, 0.f}, {1.f, 1.f, 1.f}, {2.f, 2.f, 2.f}};
  line->indices = {0, 1, 2};
  TriangleMeshShape flat(line, false, true);
  TriangleMeshShape empty(std::make_shared<MeshData>(), false, true);
  auto area_sphere = make_area_light(point_sphere, l);
  auto area_mesh = make_area_light(flat, l);
  auto area_empty = make_area_light(empty, l);
  auto tri = make_triangle_light(flat, 0, l);
  ASSERT_EQ(point_sphere.area(), 0.f);
  expect_no_emission(*area_sphere, "area on a sphere of radius 0");
  expect_no_emission(*area_mesh, "area on a zero-area mesh");
  expect_no_emission(*area_empty, "area on a mesh without triangles");
  expect_no_emission(*tri, "triangle of zero area");
  float pdf_pos = -1.f, pdf_dir = -1.f;
  tri->pdf_le(Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.f, 1.f), pdf_pos, pdf_dir);
  EXPECT_EQ(pdf_pos, 0.f);  // no point of it could have been sampled
}

TEST(EmissionDegenerate, DistantLightsNeedASceneWithExtent) {
  // A scene that is one point (or empty) has no cross-section for a distant light to cross.
  Bounds3 point;
  point.extend(Vec3(1.f, 2.f, 3.f));
  const Rgb l(1.f);
  std::vector<std::pair<const char*, std::unique_ptr<Light>>> lights;
  lights.emplace_back("directional", make_directional_light(Vec3(0.f, 0.f, 1.f), l));
  lights.emplace_back("constant", std::make_unique<ConstantLight>(l));
  lights.emplace_back("envmap", std::make_unique<EnvmapLight>(test::emission_test_map(), 1.f, Transform()));
  for (const Bounds3& b : {point, Bounds3()}) {
    for (auto& [name, light] : lights) {
      light->preprocess(b);
      expect_no_emission(*light, name);
      float pdf_pos = -1.f, pdf_dir = -1.f;
      light->pdf_le(Vec3(0.f), Vec3(0.f), Vec3(0.f, 0.f, 1.f), pdf_pos, pdf_dir);
      EXPECT_EQ(pdf_pos, 0.f) << name;
    }
  }
}

}  // namespace
}  // namespace tessera
