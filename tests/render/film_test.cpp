#include "tessera/render/film.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace tessera {
namespace {

TEST(Film, MeanVarianceAndCounts) {
  Film film(TileRect{2, 3, 6, 5}, 10, 10);
  EXPECT_EQ(film.width(), 4);
  EXPECT_EQ(film.height(), 2);
  FilmTile tile(TileRect{2, 3, 4, 5});
  tile.add_sample({3, 4}, Rgb(1.f, 2.f, 3.f));
  tile.add_sample({3, 4}, Rgb(3.f, 2.f, 1.f));
  film.add_tile(tile);
  film.add_counters(tile.counters);
  Rgb m = film.mean({3, 4});
  EXPECT_EQ(m, Rgb(2.f, 2.f, 2.f));
  Rgb v = film.sample_variance({3, 4});
  EXPECT_FLOAT_EQ(v.r, 2.f);  // samples 1 and 3
  EXPECT_FLOAT_EQ(v.g, 0.f);
  EXPECT_EQ(film.pixel({3, 4}).count, 2u);
  EXPECT_EQ(film.pixel({2, 3}).count, 0u);
  EXPECT_EQ(film.counters().samples, 2u);

  Image img = film.to_image();
  ASSERT_EQ(img.width(), 4);
  ASSERT_EQ(img.height(), 2);
  EXPECT_EQ(img.rgb(1, 1), Rgb(2.f, 2.f, 2.f));
  EXPECT_EQ(img.rgb(0, 0), Rgb());
  std::vector<float> rgb = film.to_rgb();
  EXPECT_EQ(rgb[(1 * 4 + 1) * 3], 2.f);
}

TEST(Film, ImageConvertedInBandsIsTheWholeImage) {
  // A window off the origin, every pixel different.
  Film film(TileRect{3, 2, 10, 9}, 12, 12);
  FilmTile tile(TileRect{3, 2, 10, 9});
  for (int y = 2; y < 9; ++y)
    for (int x = 3; x < 10; ++x) tile.add_sample({x, y}, Rgb(float(x), float(y), float(x * y)));
  film.add_tile(tile);
  const Image whole = film.to_image();
  Image bands(film.width(), film.height(), 3);
  for (int y = 0; y < film.height(); y += 3) film.to_image_rows(bands, y, std::min(film.height(), y + 3));
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      EXPECT_EQ(bands.rgb(x, y), whole.rgb(x, y)) << x << "," << y;
      EXPECT_EQ(whole.rgb(x, y), Rgb(float(x + 3), float(y + 2), float((x + 3) * (y + 2))));
    }
}

TEST(Film, NonFiniteSamplesDroppedAndCounted) {
  FilmTile tile(TileRect{0, 0, 1, 1});
  tile.add_sample({0, 0}, Rgb(1.f));
  tile.add_sample({0, 0}, Rgb(std::numeric_limits<float>::quiet_NaN(), 0.f, 0.f));
  tile.add_sample({0, 0}, Rgb(0.f, std::numeric_limits<float>::infinity(), 0.f));
  tile.add_sample({0, 0}, Rgb(2.f));
  EXPECT_EQ(tile.counters.nonfinite, 2u);
  EXPECT_EQ(tile.counters.samples, 4u);
  const PixelSums& px = tile.pixel({0, 0});
  EXPECT_EQ(px.count, 4u);
  EXPECT_EQ(px.sum[0], 3.0);
  EXPECT_EQ(px.sum[1], 3.0);
  EXPECT_EQ(px.sum_sq[2], 5.0);
  Film film(TileRect{0, 0, 1, 1}, 1, 1);
  film.add_tile(tile);
  EXPECT_TRUE(film.mean({0, 0}).is_finite());
  EXPECT_FLOAT_EQ(film.mean({0, 0}).g, 0.75f);
}

TEST(Film, WindowFromCrop) {
  FilmSettings s;
  s.width = 100;
  s.height = 50;
  EXPECT_EQ(film_window(s), (TileRect{0, 0, 100, 50}));
  s.crop_x = 10;
  s.crop_y = 5;
  s.crop_width = 20;
  s.crop_height = 7;
  EXPECT_EQ(film_window(s), (TileRect{10, 5, 30, 12}));
}

TEST(Renderer, PassScheduleDoublesThenCaps) {
  EXPECT_EQ(pass_schedule(0), std::vector<uint32_t>{});
  EXPECT_EQ(pass_schedule(1), std::vector<uint32_t>{1});
  EXPECT_EQ(pass_schedule(4), (std::vector<uint32_t>{1, 2, 1}));
  EXPECT_EQ(pass_schedule(7), (std::vector<uint32_t>{1, 2, 4}));
  EXPECT_EQ(pass_schedule(200), (std::vector<uint32_t>{1, 2, 4, 8, 16, 32, 64, 64, 9}));
  for (uint32_t spp : {1u, 3u, 64u, 100u, 1000u, 4096u}) {
    auto p = pass_schedule(spp);
    EXPECT_EQ(std::accumulate(p.begin(), p.end(), 0u), spp);
    for (uint32_t n : p) {
      EXPECT_GE(n, 1u);
      EXPECT_LE(n, 64u);
    }
  }
}

TEST(Renderer, TilesCoverWindowExactlyOnce) {
  TileRect window{3, 2, 103, 77};
  for (int size : {1, 8, 32, 64, 500}) {
    auto tiles = make_tiles(window, size);
    std::vector<int> hits(size_t(window.area()), 0);
    for (const TileRect& t : tiles) {
      EXPECT_TRUE(window.contains(t));
      EXPECT_LE(t.width(), size);
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) ++hits[size_t((y - 2) * 100 + (x - 3))];
    }
    for (int h : hits) ASSERT_EQ(h, 1);
  }
}

}  // namespace
}  // namespace tessera
