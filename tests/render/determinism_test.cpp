// Bit-identical films whatever the thread count, tile size or machine a tile pass ran on.
#include "scene_builders.h"
#include "tessera/sequence/renderer.h"
#include "tessera/render/sampler.h"

#include <gtest/gtest.h>

#include <cstring>

namespace tessera {
namespace {

using namespace tessera::test;

// Spheres, a cube mesh, an area light and a point light; odd film size so tiles are ragged; a
// gaussian filter; 21 spp = passes 1, 2, 4, 8, 6.
std::unique_ptr<Scene> busy_scene(SamplerType sampler) {
  auto scene = std::make_unique<Scene>();
  const Bsdf* grey = add_diffuse(*scene, Rgb(0.6f));
  const Bsdf* red = add_diffuse(*scene, Rgb(0.7f, 0.1f, 0.1f));
  auto two = make_twosided_bsdf(red, nullptr);
  scene->bsdfs.push_back(two);
  scene->shapes.push_back(std::make_unique<TriangleMeshShape>(cube_mesh(3.f, true), false, true));
  scene->shapes.back()->bsdf = grey;
  add_sphere(*scene, Vec3(-1.f, -1.f, 1.f), 0.8f, false, two.get());
  Shape* lamp = add_sphere(*scene, Vec3(1.f, 2.f, 1.5f), 0.4f, false, grey);
  add_area_light(*scene, *lamp, Rgb(8.f, 7.f, 5.f));
  scene->lights.push_back(make_point_light(Vec3(-2.f, 2.f, -1.f), Rgb(3.f)));
  set_camera(*scene, Vec3(0.f, 0.f, -2.5f), 70.f, 53, 37);
  scene->film.filter = make_gaussian_filter(0.5f, 2.f);
  scene->sampler.type = sampler;
  scene->integrator.max_depth = 8;
  scene->integrator.rr_depth = 2;
  scene->finalize();
  return scene;
}

bool same_bits(const Film& a, const Film& b) {
  if (!(a.window() == b.window())) return false;
  for (int y = a.window().y0; y < a.window().y1; ++y)
    for (int x = a.window().x0; x < a.window().x1; ++x)
      if (std::memcmp(&a.pixel({x, y}), &b.pixel({x, y}), sizeof(PixelSums)) != 0) return false;
  return true;
}

TEST(Determinism, ThreadsAndTileSizesGiveIdenticalBits) {
  for (SamplerType type : {SamplerType::Sobol, SamplerType::Independent}) {
    auto scene = busy_scene(type);
    RenderSettings s;
    s.spp = 21;
    s.seed = 9;
    s.threads = 1;
    s.tile_size = 8;
    RenderStats ref_stats;
    Film ref = render(*scene, s, {}, &ref_stats);
    EXPECT_GT(ref.mean({26, 18}).average(), 0.f);
    for (int threads : {1, 2})
      for (int tile : {8, 32, 64}) {
        if (threads == 1 && tile == 8) continue;
        s.threads = threads;
        s.tile_size = tile;
        RenderStats stats;
        Film f = render(*scene, s, {}, &stats);
        EXPECT_TRUE(same_bits(ref, f)) << threads << " threads, tile " << tile;
        EXPECT_EQ(stats.counters.rays(), ref_stats.counters.rays());
        EXPECT_EQ(stats.counters.samples, ref_stats.counters.samples);
      }
    // A different seed gives a different image (so the comparison above can fail).
    s.seed = 10;
    EXPECT_FALSE(same_bits(ref, render(*scene, s)));
  }
}

// A tile pass rendered on its own (as a farm worker would) has exactly the bits of the same pixels
// and samples inside a full render: here spp = 3 is passes {1, 2}; render both passes of one tile
// separately and add them in pass order.
TEST(Determinism, StandaloneTilePassesReproduceFullRender) {
  auto scene = busy_scene(SamplerType::Sobol);
  RenderSettings s;
  s.spp = 3;
  s.seed = 4;
  s.threads = 2;
  s.tile_size = 16;
  Film full = render(*scene, s);

  TileRect rect{5, 7, 29, 20};
  Film part(film_window(scene->film), scene->film.width, scene->film.height);
  FilmTile tile;
  render_tile(*scene, rect, 0, 1, s.seed, tile);
  part.add_tile(tile);
  render_tile(*scene, rect, 1, 3, s.seed, tile);
  part.add_tile(tile);
  for (int y = rect.y0; y < rect.y1; ++y)
    for (int x = rect.x0; x < rect.x1; ++x)
      ASSERT_EQ(std::memcmp(&full.pixel({x, y}), &part.pixel({x, y}), sizeof(PixelSums)), 0)
          << "pixel " << x << "," << y;
}

TEST(Determinism, ProgressReportsEveryTile) {
  auto scene = busy_scene(SamplerType::Sobol);
  RenderSettings s;
  s.spp = 4;  // passes 1, 2, 1
  s.threads = 2;
  s.tile_size = 32;
  int64_t calls = 0, last_done = 0, total = 0;
  render(*scene, s, [&](const RenderProgress& p) {
    ++calls;
    EXPECT_EQ(p.tiles_done, last_done + 1);
    last_done = p.tiles_done;
    total = p.tiles_total;
    EXPECT_EQ(p.num_passes, 3);
  });
  EXPECT_EQ(total, 2 * 2 * 3);  // 53x37 in 32-pixel tiles, 3 passes
  EXPECT_EQ(calls, total);
}

}  // namespace
}  // namespace tessera
