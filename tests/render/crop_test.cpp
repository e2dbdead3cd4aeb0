// Film crop windows: a cropped render equals the same pixels of the full render, bit for bit (each
// pixel's value depends only on scene, pixel, sample index and seed).
#include "scene_builders.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

using namespace tessera::test;

TEST(Crop, CroppedRenderEqualsFullRenderPixels) {
  Scene scene;
  add_sphere(scene, {0.f, 0.f, 4.f}, 1.f, false, add_diffuse(scene, Rgb(0.6f, 0.5f, 0.4f)));
  add_sphere(scene, {0.f, -101.f, 4.f}, 100.f, false, add_diffuse(scene, Rgb(0.5f)));
  scene.lights.push_back(make_point_light({2.f, 3.f, 1.f}, Rgb(20.f)));
  // A lens camera, so that the lens samples are part of what must not depend on the window.
  scene.camera = make_thinlens_camera(Transform(), 45.f, 40, 30, 1e-3f, 1e4f, 0.1f, 4.f);
  scene.film.width = 40;
  scene.film.height = 30;
  scene.film.filter = make_gaussian_filter(0.5f, 2.f);
  scene.finalize();
  RenderSettings rs = test::render_settings(8, 9, 8);
  Film full = render(scene, rs);

  scene.film.crop_x = 7;
  scene.film.crop_y = 5;
  scene.film.crop_width = 17;
  scene.film.crop_height = 11;
  rs.tile_size = 5;  // different tiling as well
  Film crop = render(scene, rs);
  ASSERT_EQ(crop.window(), (TileRect{7, 5, 24, 16}));
  ASSERT_EQ(crop.width(), 17);
  int nonzero = 0;
  for (int y = 5; y < 16; ++y)
    for (int x = 7; x < 24; ++x) {
      const PixelSums &a = full.pixel({x, y}), &b = crop.pixel({x, y});
      ASSERT_EQ(a.count, b.count);
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(a.sum[c], b.sum[c]) << "pixel " << x << "," << y;
        ASSERT_EQ(a.sum_sq[c], b.sum_sq[c]) << "pixel " << x << "," << y;
      }
      nonzero += a.sum[1] > 0;
    }
  EXPECT_GT(nonzero, 100);  // the window sees the lit scene, not just black
}

}  // namespace
}  // namespace tessera
