// Accumulation: a million samples into one pixel do not drift, and however the work is split into
// tiles and passes the sums are the same bits.
#include "hardcases/hardcase_support.h"
#include "render/scene_builders.h"
#include "tessera/light/constant.h"

#include <algorithm>
#include <cstring>

namespace tessera {
namespace {

// Expected: the film's sums are doubles, so 1e6 copies of 0.1f (24 significant bits) add exactly
// (the sum needs at most 24 + 20 bits < 53) and the mean is 0.1f to the last bit; a float sum would
// be off by ~1e-3 relative (its spacing at 1e5 is 0.008, wider than 0.1f's own bits reach).
// Checked to 1e-9 relative, with the sum of squares to 1e-9 too.
TEST(HardAccumulation, MillionSamplesOfOneTenthInOnePixel) {
  FilmTile tile(TileRect{0, 0, 1, 1});
  constexpr int kN = 1000000;
  for (int i = 0; i < kN; ++i) tile.add_sample({0, 0}, Rgb(0.1f));
  Film film(TileRect{0, 0, 1, 1}, 1, 1);
  film.add_tile(tile);
  const double expect = double(0.1f);
  EXPECT_EQ(film.pixel({0, 0}).count, uint64_t(kN));
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(film.mean({0, 0})[c], expect, 1e-9 * expect);
    EXPECT_NEAR(film.pixel({0, 0}).sum_sq[c] / kN, expect * expect, 1e-9 * expect * expect);
  }
  EXPECT_EQ(film.pixel({0, 0}).sum[0], kN * expect) << "exact in double";
  EXPECT_NEAR(film.sample_variance({0, 0}).g, 0.f, 1e-12f);
}

// The same through the renderer: 1e6 spp of a 1x1 film looking into a constant environment of 0.1
// (every camera ray escapes and returns exactly 0.1f): ~15,600 passes, whose per-pass sums the film
// adds in order. Expected: mean 0.1f to 1e-9 relative, 1e6 samples counted, nothing non-finite.
TEST(HardAccumulation, MillionSamplesThroughTheRenderer) {
  Scene scene;
  scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(0.1f)));
  test::set_camera(scene, Vec3(0.f), 45.f, 1, 1);
  scene.finalize();
  RenderStats stats;
  Film film = test::render_checked(scene, test::hard_settings(1000000), "1e6 spp", &stats);
  EXPECT_EQ(film.pixel({0, 0}).count, 1000000u);
  EXPECT_EQ(stats.counters.samples, 1000000u);
  const double expect = double(0.1f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(film.mean({0, 0})[c], expect, 1e-9 * expect);
}

bool same_bits(const Film& a, const Film& b) {
  if (a.window() != b.window()) return false;
  for (int y = a.window().y0; y < a.window().y1; ++y)
    for (int x = a.window().x0; x < a.window().x1; ++x)
      if (std::memcmp(&a.pixel({x, y}), &b.pixel({x, y}), sizeof(PixelSums)) != 0) return false;
  return true;
}

// Expected: bit-identical sums (renderer.h's determinism contract) for one 64-pixel tile, 3-pixel
// tiles (ragged at the edges), and passes of 3-pixel tiles added to a film by hand in a shuffled
// tile order, on a two-sphere scene at 100 spp (passes 1,2,4,8,16,64 + remainder 5).
TEST(HardAccumulation, ManySmallTilesAddExactlyAsOneBigOne) {
  Scene scene;
  const Bsdf* white = test::add_diffuse(scene, Rgb(0.8f));
  test::add_sphere(scene, Vec3(0.f, 0.f, 3.f), 1.f, false, white);
  Shape* lamp = test::add_sphere(scene, Vec3(1.f, 1.5f, 2.f), 0.3f, false, white);
  test::add_area_light(scene, *lamp, Rgb(20.f));
  scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(0.05f)));
  test::set_camera(scene, Vec3(0.f), 45.f, 20, 14);
  scene.finalize();

  constexpr int kSpp = 100;
  RenderSettings big = test::hard_settings(kSpp);
  big.tile_size = 64;
  RenderSettings small = big;
  small.tile_size = 3;
  const Film a = test::render_checked(scene, big, "one tile");
  const Film b = test::render_checked(scene, small, "3-pixel tiles");
  EXPECT_TRUE(same_bits(a, b));

  Film c(scene.film);
  std::vector<TileRect> tiles = make_tiles(film_window(scene.film), 3);
  std::reverse(tiles.begin(), tiles.end());  // any tile order; pass order is what matters
  uint32_t begin = 0;
  for (uint32_t n : pass_schedule(kSpp)) {
    for (const TileRect& r : tiles) {
      FilmTile t;
      render_tile(scene, r, begin, begin + n, big.seed, t);
      EXPECT_EQ(t.counters.nonfinite, 0u);
      c.add_tile(t);
    }
    begin += n;
  }
  EXPECT_EQ(begin, uint32_t(kSpp));
  EXPECT_TRUE(same_bits(a, c));
  EXPECT_EQ(a.pixel({10, 7}).count, uint64_t(kSpp));
}

}  // namespace
}  // namespace tessera
