// A Paths unit's result on the wire (farm/splat_result.h): exact round trips, compressed or
// stored; told apart from tile results; anything damaged, out of its window or over its paths'
// bound refused.
#include "tessera/farm/splat_result.h"
#include "tessera/farm/tile_result.h"

#include <gtest/gtest.h>

#include <random>

namespace tessera::test {
namespace {

SplatResult sample_result(size_t splats) {
  SplatResult r;
  r.job_id = 42;
  r.pass = 3;
  r.unit = 7;
  r.path_begin = 1000;
  r.path_end = 1000 + splats;
  r.seconds = 1.5;
  r.splats.reset({2, 3, 34, 19});
  std::mt19937 rng(5);
  for (size_t i = 0; i < splats; ++i) {
    r.splats.pixel.push_back(uint32_t(rng() % (32 * 16)));
    r.splats.value.push_back({std::ldexp(double(rng()), -20), double(rng() % 7), 1e-30 * double(rng())});
  }
  r.splats.counters.samples = splats;
  r.splats.counters.shadow_rays = 3 * splats;
  r.records = "records";
  return r;
}

void expect_equal(const SplatResult& a, const SplatResult& b) {
  EXPECT_EQ(a.job_id, b.job_id);
  EXPECT_EQ(a.pass, b.pass);
  EXPECT_EQ(a.unit, b.unit);
  EXPECT_EQ(a.path_begin, b.path_begin);
  EXPECT_EQ(a.path_end, b.path_end);
  EXPECT_EQ(a.seconds, b.seconds);
  EXPECT_EQ(a.splats.window, b.splats.window);
  EXPECT_EQ(a.splats.pixel, b.splats.pixel);
  EXPECT_EQ(a.splats.value, b.splats.value) << "every double's bits";
  EXPECT_EQ(a.splats.counters.samples, b.splats.counters.samples);
  EXPECT_EQ(a.splats.counters.shadow_rays, b.splats.counters.shadow_rays);
  EXPECT_EQ(a.records, b.records);
}

TEST(SplatResult, RoundTripsCompressedAndStored) {
  const SplatResult r = sample_result(300);
  for (int level : {1, 3, kUncompressed}) {
    const std::string bytes = encode_splat_result(r, level);
    EXPECT_TRUE(is_splat_result(bytes)) << level;
    SplatResult back;
    std::string error;
    ASSERT_TRUE(decode_splat_result(bytes, back, error)) << error;
    expect_equal(r, back);
    EXPECT_LT(bytes.size(), max_splat_result_bytes(r.path_end - r.path_begin, r.records.size()));
  }
  TileResult tile;
  tile.film.reset({0, 0, 4, 4});
  EXPECT_FALSE(is_splat_result(encode_tile_result(tile))) << "a tile result is told apart";
  EXPECT_FALSE(is_splat_result(encode_tile_result(tile, kUncompressed)));
  EXPECT_FALSE(is_splat_result("junk"));
}

// A light tracer's unit over a large window: megabytes of random-looking doubles, whose first
// compressed block takes more than 64 KiB before it gives the magic out.
TEST(SplatResult, ALargeResultIsToldApartFromATile) {
  const SplatResult r = sample_result(200000);
  const std::string bytes = encode_splat_result(r);
  ASSERT_GT(bytes.size(), size_t(1) << 20);
  EXPECT_TRUE(is_splat_result(bytes));
  SplatResult back;
  std::string error;
  ASSERT_TRUE(decode_splat_result(bytes, back, error)) << error;
  expect_equal(r, back);
}

TEST(SplatResult, DamageAndSplatsOutsideTheirBoundsAreRefused) {
  const SplatResult r = sample_result(40);
  const std::string stored = encode_splat_result(r, kUncompressed);
  std::string error;
  SplatResult out;
  for (size_t i = 0; i < stored.size(); i += 7) {
    std::string bad = stored;
    bad[i] = char(bad[i] ^ 0x20);
    EXPECT_FALSE(decode_splat_result(bad, out, error)) << "flipped byte " << i;
  }
  EXPECT_FALSE(decode_splat_result(stored.substr(0, stored.size() - 1), out, error));
  EXPECT_FALSE(decode_splat_result(encode_splat_result(r).substr(0, 20), out, error));
  SplatResult outside = r;
  outside.splats.pixel[5] = 32 * 16;  // (one past the window's last pixel)
  EXPECT_FALSE(decode_splat_result(encode_splat_result(outside), out, error));
  EXPECT_NE(error.find("outside the window"), std::string::npos) << error;
  SplatResult crowded = r;
  crowded.path_end = crowded.path_begin;  // (40 splats from no path)
  EXPECT_FALSE(decode_splat_result(encode_splat_result(crowded), out, error));
  SplatResult nan = r;
  nan.splats.value[3][1] = std::nan("");
  EXPECT_FALSE(decode_splat_result(encode_splat_result(nan), out, error)) << "no NaN reaches a film";
}

}  // namespace
}  // namespace tessera::test
