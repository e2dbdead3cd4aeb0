#include "tessera/render/sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <vector>

namespace tessera {
namespace {

// Draws `dims_before` 1D values, then returns the next 2D value.
Vec2 draw_2d(Sampler& s, Vec2i pixel, uint32_t index, int dims_before) {
  s.start_pixel_sample(pixel, index);
  for (int i = 0; i < dims_before; ++i) s.next_1d();
  return s.next_2d();
}

TEST(Sampler, ValuesInUnitInterval) {
  for (SamplerType type : {SamplerType::Sobol, SamplerType::Independent}) {
    Sampler s(type, 7);
    for (int px = 0; px < 16; ++px)
      for (uint32_t i = 0; i < 256; ++i) {
        s.start_pixel_sample({px, 3 * px}, i);
        for (int d = 0; d < 10; ++d) {
          float a = s.next_1d();
          Vec2 b = s.next_2d();
          ASSERT_GE(a, 0.f);
          ASSERT_LT(a, 1.f);
          ASSERT_GE(b.x, 0.f);
          ASSERT_LT(b.x, 1.f);
          ASSERT_GE(b.y, 0.f);
          ASSERT_LT(b.y, 1.f);
        }
      }
  }
}

TEST(Sampler, DimensionCounter) {
  Sampler s(SamplerType::Sobol, 0);
  s.start_pixel_sample({1, 2}, 3);
  s.next_2d();
  s.next_2d();
  EXPECT_EQ(s.dimension(), 4u);
  s.next_1d();
  EXPECT_EQ(s.dimension(), 5u);
  s.start_pixel_sample({1, 2}, 4);
  EXPECT_EQ(s.dimension(), 0u);
}

// A value depends on (pixel, index, dimension, seed) only, not on what was asked before.
TEST(Sampler, DeterministicAndHistoryFree) {
  for (SamplerType type : {SamplerType::Sobol, SamplerType::Independent}) {
    Sampler a(type, 42), b(type, 42);
    std::vector<float> first;
    for (uint32_t i = 0; i < 64; ++i) {
      a.start_pixel_sample({5, 9}, i);
      first.push_back(a.next_1d());
      Vec2 v = a.next_2d();
      first.push_back(v.x);
      first.push_back(v.y);
    }
    // Visit the samples backwards, with unrelated pixels in between.
    for (int i = 63; i >= 0; --i) {
      b.start_pixel_sample({100, 1}, uint32_t(i) * 7);
      b.next_2d();
      b.start_pixel_sample({5, 9}, uint32_t(i));
      float x = b.next_1d();
      Vec2 v = b.next_2d();
      EXPECT_EQ(x, first[size_t(3 * i)]);
      EXPECT_EQ(v.x, first[size_t(3 * i + 1)]);
      EXPECT_EQ(v.y, first[size_t(3 * i + 2)]);
    }
  }
}

// Owen-scrambled Sobol is a (0,2)-sequence in every 2D request: the first 2^k samples of a pixel
// have exactly one point in each elementary interval of area 2^-k (all 2^a x 2^(k-a) shapes).
TEST(Sampler, SobolElementaryIntervals2D) {
  Sampler s(SamplerType::Sobol, 3);
  for (Vec2i pixel : {Vec2i{0, 0}, Vec2i{17, 5}, Vec2i{1023, 767}}) {
    for (int dims_before : {0, 2, 5}) {  // dims 0-1, then later padded pairs
      for (int k = 0; k <= 10; ++k) {
        const uint32_t n = 1u << k;
        std::vector<Vec2> pts;
        for (uint32_t i = 0; i < n; ++i) pts.push_back(draw_2d(s, pixel, i, dims_before));
        for (int a = 0; a <= k; ++a) {
          const uint32_t nx = 1u << a, ny = 1u << (k - a);
          std::vector<int> count(size_t(n), 0);
          for (Vec2 p : pts) {
            uint32_t cx = uint32_t(p.x * float(nx)), cy = uint32_t(p.y * float(ny));
            ++count[size_t(cy * nx + cx)];
          }
          for (int c : count)
            ASSERT_EQ(c, 1) << "pixel (" << pixel.x << "," << pixel.y << ") dims_before " << dims_before
                            << " k=" << k << " shape " << nx << "x" << ny;
        }
      }
    }
  }
}

TEST(Sampler, SobolStratified1D) {
  Sampler s(SamplerType::Sobol, 11);
  for (int dims_before : {0, 1, 4}) {
    for (int k = 0; k <= 12; ++k) {
      const uint32_t n = 1u << k;
      std::vector<int> count(n, 0);
      for (uint32_t i = 0; i < n; ++i) {
        s.start_pixel_sample({3, 4}, i);
        for (int d = 0; d < dims_before; ++d) s.next_1d();
        ++count[size_t(s.next_1d() * float(n))];
      }
      for (int c : count) ASSERT_EQ(c, 1) << "k=" << k << " dims_before " << dims_before;
    }
  }
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double n = double(a.size()), ma = 0, mb = 0;
  for (size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= n, mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

// Across a 64x64 block of pixels, sample 0 of neighbouring pixels, of different seeds and of
// different dimensions must be uncorrelated (|r| well under 5 / sqrt(4096)), and sample 0 itself
// must be uniform over pixels (each of 16 bins within 5 sigma).
TEST(Sampler, PixelsSeedsAndDimensionsDecorrelated) {
  for (SamplerType type : {SamplerType::Sobol, SamplerType::Independent}) {
    Sampler s1(type, 1), s2(type, 2);
    std::vector<double> v, right, below, other_seed, later_dim;
    std::vector<int> bins(16, 0);
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 64; ++x) {
        s1.start_pixel_sample({x, y}, 0);
        Vec2 p = s1.next_2d();
        Vec2 q = s1.next_2d();
        v.push_back(p.x);
        later_dim.push_back(q.x);
        ++bins[size_t(p.x * 16.f)];
        s1.start_pixel_sample({x + 1, y}, 0);
        right.push_back(s1.next_2d().x);
        s1.start_pixel_sample({x, y + 1}, 0);
        below.push_back(s1.next_2d().x);
        s2.start_pixel_sample({x, y}, 0);
        other_seed.push_back(s2.next_2d().x);
      }
    const double limit = 5.0 / std::sqrt(double(v.size()));
    EXPECT_LT(std::abs(correlation(v, right)), limit);
    EXPECT_LT(std::abs(correlation(v, below)), limit);
    EXPECT_LT(std::abs(correlation(v, other_seed)), limit);
    EXPECT_LT(std::abs(correlation(v, later_dim)), limit);
    const double expected = double(v.size()) / 16.0, sigma = std::sqrt(expected * (15.0 / 16.0));
    for (int c : bins) EXPECT_LT(std::abs(c - expected), 5 * sigma);
    // And the sequences really differ.
    EXPECT_NE(v, other_seed);
  }
}

// Scrambling must not leave structure in the sequence of one pixel either: the per-pixel sample
// sets of different pixels are distinct (no two pixels share their first 16 points).
TEST(Sampler, PixelsGetDistinctPointSets) {
  Sampler s(SamplerType::Sobol, 0);
  std::set<std::vector<float>> seen;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      std::vector<float> pts;
      for (uint32_t i = 0; i < 16; ++i) {
        Vec2 p = draw_2d(s, {x, y}, i, 0);
        pts.push_back(p.x);
        pts.push_back(p.y);
      }
      EXPECT_TRUE(seen.insert(pts).second);
    }
}

// Owen-scrambled Sobol integrates a smooth function with error far below independent sampling.
TEST(Sampler, SobolConvergesFasterThanIndependent) {
  auto error = [](SamplerType type) {
    double total = 0;
    for (int px = 0; px < 32; ++px) {
      Sampler s(type, 5);
      double sum = 0;
      const uint32_t n = 256;
      for (uint32_t i = 0; i < n; ++i) {
        s.start_pixel_sample({px, 0}, i);
        Vec2 u = s.next_2d();
        sum += std::sin(3.0 * u.x) * std::exp(u.y);  // integral: (1-cos 3)/3 * (e-1)
      }
      double exact = (1.0 - std::cos(3.0)) / 3.0 * (std::exp(1.0) - 1.0);
      total += std::abs(sum / n - exact);
    }
    return total / 32;
  };
  double sobol = error(SamplerType::Sobol), indep = error(SamplerType::Independent);
  EXPECT_LT(sobol * 10, indep) << "sobol " << sobol << " independent " << indep;
}

TEST(Sampler, SobolFirstDimensionsMatchKnownPoints) {
  // Unscrambled dims: index 1 -> (1/2, 1/2), 2 -> (1/4, 3/4), 3 -> (3/4, 1/4).
  EXPECT_EQ(sobol::sample(1, 0), 0x80000000u);
  EXPECT_EQ(sobol::sample(1, 1), 0x80000000u);
  EXPECT_EQ(sobol::sample(2, 0), 0x40000000u);
  EXPECT_EQ(sobol::sample(2, 1), 0xC0000000u);
  EXPECT_EQ(sobol::sample(3, 0), 0xC0000000u);
  EXPECT_EQ(sobol::sample(3, 1), 0x40000000u);
  // The scramble is a bijection on aligned blocks: it permutes 0..255 shifted to the top bits.
  std::set<uint32_t> tops;
  for (uint32_t i = 0; i < 256; ++i) tops.insert(sobol::nested_uniform_scramble(i << 24, 12345) >> 24);
  EXPECT_EQ(tops.size(), 256u);
}

}  // namespace
}  // namespace tessera
