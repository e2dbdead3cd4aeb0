// Furnace: in a constant environment of radiance 1, lossless smooth dielectrics (spheres and a
// closed mesh cube; IOR 1.5 and 1.33; specular reflectance and transmittance 1) are invisible:
// every path through them escapes to the environment with weight R/P(R) = T/P(T) = 1 (the eta^2
// radiance scaling cancels between entering and leaving), so their pixels stay 1. A diffuse
// control sphere of albedo 0.5 in the same furnace is 0.5 (a convex object sees only the
// environment) and must not pass for 1. The control is rendered on its own: seen through or
// reflected in the dielectrics it would (rightly) darken their pixels.
#include "scene_builders.h"
#include "tessera/bsdf/dielectric.h"
#include "tessera/light/constant.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>

namespace tessera {
namespace {

using namespace tessera::test;

const Bsdf* add_dielectric(Scene& scene, float eta) {
  auto one = std::make_shared<ConstantTexture>(Rgb(1.f));
  scene.bsdfs.push_back(make_dielectric_bsdf(eta, one, one));
  return scene.bsdfs.back().get();
}

constexpr int kWidth = 64, kHeight = 48;

Film render_furnace(Scene& scene, int rr_depth = 5) {
  scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
  set_camera(scene, Vec3(0.f), 40.f, kWidth, kHeight);
  scene.film.filter = make_box_filter(0.5f);
  scene.sampler.type = SamplerType::Independent;
  scene.integrator.type = IntegratorType::Path;
  scene.integrator.max_depth = 64;  // the chance that a path is still inside after 64 bounces is negligible
  scene.integrator.rr_depth = rr_depth;
  scene.finalize();
  return render(scene, render_settings(32, 5));
}

struct Stats {
  double sum = 0, worst = 0;  // worst: largest |pixel - expected|
  double var_sum = 0;         // sum over pixels of the variance of the pixel's mean
  int n = 0;
  double mean() const { return sum / std::max(n, 1); }
  double mean_se() const { return std::sqrt(var_sum) / std::max(n, 1); }
};

Stats pixels_of(const Scene& scene, const Film& film, const Shape* shape, double expected) {
  Stats st;
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      auto c = cover(scene, x, y);
      if (!c || *c != shape) continue;
      Rgb m = film.mean({x, y}), var = film.sample_variance({x, y});
      double count = double(film.pixel({x, y}).count);
      for (int ch = 0; ch < 3; ++ch) {
        st.worst = std::max(st.worst, std::abs(double(m[ch]) - expected));
      }
      st.sum += (double(m.r) + m.g + m.b) / 3.0;
      st.var_sum += (double(var.r) + var.g + var.b) / 3.0 / count;
      ++st.n;
    }
  return st;
}

struct Objects {
  const Shape *glass, *water, *cube;
};

Objects add_dielectric_objects(Scene& scene) {
  Objects o;
  o.glass = add_sphere(scene, {-1.2f, 0.3f, 6.f}, 0.55f, false, add_dielectric(scene, 1.5f));
  o.water = add_sphere(scene, {0.f, -0.4f, 6.f}, 0.6f, false, add_dielectric(scene, 1.33f));
  // A closed cube, rotated so that no face is parallel to the film, as a triangle mesh.
  auto cube = cube_mesh(0.42f, /*inward=*/false);
  const Transform xf = Transform::translate({1.2f, 0.3f, 6.f}) * Transform::rotate({1.f, 1.f, 0.f}, 35.f);
  for (Vec3& p : cube->positions) p = xf.apply_point(p);
  scene.shapes.push_back(std::make_unique<TriangleMeshShape>(cube, false, true));
  scene.shapes.back()->bsdf = add_dielectric(scene, 1.5f);
  o.cube = scene.shapes.back().get();
  return o;
}

// Without Russian roulette (rr_depth beyond max_depth) every sample is exactly 1 up to float
// rounding: any deviation is a bug (lost or created energy, a leak through the mesh).
TEST(Furnace, LosslessDielectricsStayOneExactly) {
  Scene scene;
  Objects o = add_dielectric_objects(scene);
  Film film = render_furnace(scene, /*rr_depth=*/1000);
  for (auto [shape, name] : {std::pair{o.glass, "glass sphere"}, {o.water, "water sphere"}, {o.cube, "glass cube"},
                             {static_cast<const Shape*>(nullptr), "background"}}) {
    Stats st = pixels_of(scene, film, shape, 1.0);
    std::printf("[ furnace  ] no RR: %-12s %4d pixels: mean %.7f, worst |pixel - 1| %.2e\n", name, st.n, st.mean(),
                st.worst);
    ASSERT_GT(st.n, 50) << name;
    EXPECT_NEAR(st.mean(), 1.0, 1e-5) << name;
    EXPECT_LT(st.worst, 1e-4) << name;
  }
}

// With the default Russian roulette (from depth 5), paths inside the glass carry throughput
// 1/eta^2 < 1 and are killed or boosted: the pixels are noisy but still 1 in expectation. Mean per
// object within 4 standard errors. Per pixel, a killed path moves the mean of 32 samples by 1/32
// and a boosted one by (1/q - 1)/32 with survival q >= 1/eta^2 (0.44), about 4%: a few such events
// stay far below 0.2, which a pixel showing anything but the environment (the control's 0.5, a
// black leak) exceeds. (Per-pixel z-scores are useless here: the rare events make the sample
// variance of one pixel meaningless.)
TEST(Furnace, LosslessDielectricsStayOneWithRussianRoulette) {
  Scene scene;
  Objects o = add_dielectric_objects(scene);
  Film film = render_furnace(scene);
  for (auto [shape, name] : {std::pair{o.glass, "glass sphere"}, {o.water, "water sphere"}, {o.cube, "glass cube"}}) {
    Stats st = pixels_of(scene, film, shape, 1.0);
    std::printf("[ furnace  ] RR:    %-12s %4d pixels: mean %.5f +- %.5f, worst |pixel - 1| %.3f\n", name, st.n,
                st.mean(), st.mean_se(), st.worst);
    ASSERT_GT(st.n, 50) << name;
    // (The floor: with rare boosted paths the sample variance underestimates the true one.)
    EXPECT_NEAR(st.mean(), 1.0, std::max(4 * st.mean_se(), 5e-4)) << name;
    EXPECT_LT(st.worst, 0.2) << name;
  }
}

TEST(Furnace, DiffuseControlIsNotOne) {
  Scene scene;
  const Shape* control = add_sphere(scene, {0.f, 0.f, 6.f}, 0.8f, false, add_diffuse(scene, Rgb(0.5f)));
  Film film = render_furnace(scene);
  Stats st = pixels_of(scene, film, control, 0.5);
  std::printf("[ furnace  ] control %4d pixels: mean %.4f, worst |pixel - 0.5| %.3f\n", st.n, st.mean(), st.worst);
  ASSERT_GT(st.n, 200);
  // NEE + BSDF sampling with MIS at 32 spp: noisy, but 0.5 on average, and no pixel near 1.
  EXPECT_NEAR(st.mean(), 0.5, 0.01);
  EXPECT_LT(st.worst, 0.25);
  Stats bg = pixels_of(scene, film, nullptr, 1.0);
  EXPECT_LT(bg.worst, 1e-6);
}

}  // namespace
}  // namespace tessera
