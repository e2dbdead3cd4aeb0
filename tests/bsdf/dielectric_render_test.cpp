// The path tracer with transmissive and coated BSDFs: white furnace. Under a constant environment of
// radiance 1, a glass sphere is 1 everywhere (R + T = 1 at each interface and the 1/eta^2 of
// entering cancels the eta^2 of leaving), so is a thin-glass sphere, and so is plastic with a white
// base (its albedo is exactly 1). Rays must cross the surfaces both ways for this to hold.
#include "render/scene_builders.h"
#include "tessera/bsdf/dielectric.h"
#include "tessera/light/constant.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }

void expect_furnace_is_one(std::shared_ptr<Bsdf> bsdf, const char* what) {
  Scene scene;
  scene.bsdfs.push_back(bsdf);
  test::add_sphere(scene, Vec3(0.f, 0.f, 3.f), 1.f, false, bsdf.get());
  scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
  test::set_camera(scene, Vec3(0.f), 45.f, 16, 16);
  scene.finalize();
  Film film = render(scene, test::render_settings(64));
  double sum = 0;
  int n = 0;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      Rgb m = film.mean({x, y});
      EXPECT_NEAR(m.g, 1.f, 0.05f) << what << " pixel " << x << "," << y;
      sum += m.g;
      ++n;
    }
  EXPECT_NEAR(sum / n, 1.0, 0.005) << what;
}

TEST(DielectricRender, WhiteFurnace) {
  expect_furnace_is_one(make_dielectric_bsdf(1.5046f, constant(Rgb(1.f)), constant(Rgb(1.f))), "dielectric");
  expect_furnace_is_one(make_dielectric_bsdf(2.419f, constant(Rgb(1.f)), constant(Rgb(1.f))), "diamond");
  expect_furnace_is_one(make_thindielectric_bsdf(1.5f, constant(Rgb(1.f)), constant(Rgb(1.f))), "thindielectric");
  expect_furnace_is_one(make_plastic_bsdf(1.49f, constant(Rgb(1.f)), constant(Rgb(1.f)), false), "plastic");
}

// A tinted glass sphere: the camera sees through it only via transmission, so the pixel at the
// centre (normal incidence both ways) is about T^2 * tint^2 + (reflections): darker than 1.
TEST(DielectricRender, TransmittanceTintsTheSphere) {
  Scene scene;
  auto bsdf = make_dielectric_bsdf(1.5f, constant(Rgb(1.f)), constant(Rgb(0.5f)));
  scene.bsdfs.push_back(bsdf);
  test::add_sphere(scene, Vec3(0.f, 0.f, 3.f), 1.f, false, bsdf.get());
  scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
  test::set_camera(scene, Vec3(0.f), 45.f, 16, 16);
  scene.finalize();
  Film film = render(scene, test::render_settings(64));
  const float c = film.mean({8, 8}).g;
  EXPECT_LT(c, 0.5f);
  EXPECT_GT(c, 0.2f);
}

}  // namespace
}  // namespace tessera
