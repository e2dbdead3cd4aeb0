#include "tessera/core/distribution.h"
#include "tessera/core/hash.h"
#include "tessera/core/sampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

TEST(Warps, CosineHemisphereIsUnitAndUpper) {
  Pcg32 rng(7);
  for (int i = 0; i < 10000; ++i) {
    Vec3 w = square_to_cosine_hemisphere({rng.next_float(), rng.next_float()});
    EXPECT_NEAR(length(w), 1.f, 1e-5f);
    EXPECT_GE(w.z, 0.f);
  }
}

TEST(Warps, ConeStaysInsideCone) {
  Pcg32 rng(3);
  for (int i = 0; i < 10000; ++i) {
    Vec3 w = square_to_uniform_cone({rng.next_float(), rng.next_float()}, 0.9f);
    EXPECT_GE(w.z, 0.9f - 1e-6f);
    EXPECT_NEAR(length(w), 1.f, 1e-5f);
  }
}

TEST(Warps, TriangleBarycentricsAreValidAndUniform) {
  Pcg32 rng(11);
  // Mean of uniform barycentrics is (1/3, 1/3).
  double s1 = 0, s2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    Vec2 b = square_to_uniform_triangle({rng.next_float(), rng.next_float()});
    ASSERT_GE(b.x, 0.f);
    ASSERT_GE(b.y, 0.f);
    ASSERT_LE(b.x + b.y, 1.f + 1e-6f);
    s1 += b.x;
    s2 += b.y;
  }
  // Standard deviation of a barycentric is sqrt(1/18); 5 sigma of the mean.
  double tol = 5 * std::sqrt(1.0 / 18.0 / n);
  EXPECT_NEAR(s1 / n, 1.0 / 3.0, tol);
  EXPECT_NEAR(s2 / n, 1.0 / 3.0, tol);
}

TEST(Distribution1D, DiscreteFrequenciesFollowWeights) {
  Distribution1D d({1.f, 0.f, 3.f, 4.f});
  EXPECT_DOUBLE_EQ(d.total(), 8.0);
  EXPECT_FLOAT_EQ(d.pmf(2), 3.f / 8.f);
  int counts[4] = {0, 0, 0, 0};
  const int n = 80000;
  for (int i = 0; i < n; ++i) counts[d.sample_discrete((i + 0.5f) / n)]++;
  EXPECT_EQ(counts[1], 0);
  EXPECT_NEAR(counts[0], n / 8, 2);
  EXPECT_NEAR(counts[2], 3 * n / 8, 2);
  EXPECT_NEAR(counts[3], n / 2, 2);
}

TEST(Distribution1D, EdgesNeverPickEmptyBins) {
  Distribution1D d({0.f, 1.f, 0.f});
  EXPECT_EQ(d.sample_discrete(0.f), 1u);
  EXPECT_EQ(d.sample_discrete(0x1.fffffep-1f), 1u);
}

// The bin a binary search over the whole cdf picks (the search the guide table replaces), with
// the cdf summed and normalised as Distribution1D does.
uint32_t binary_search_bin(const std::vector<float>& w, float u) {
  std::vector<double> cdf(w.size() + 1, 0.0), f(w.size());
  for (size_t i = 0; i < w.size(); ++i) {
    f[i] = std::isfinite(w[i]) && w[i] > 0.f ? double(w[i]) : 0.0;
    cdf[i + 1] = cdf[i] + f[i];
  }
  const double sum = cdf.back();
  for (size_t i = 1; i <= w.size(); ++i) cdf[i] /= sum;
  cdf.back() = 1.0;
  auto it = std::upper_bound(cdf.begin(), cdf.end(), double(u));
  size_t i = size_t(std::clamp<std::ptrdiff_t>(it - cdf.begin() - 1, 0, std::ptrdiff_t(w.size()) - 1));
  while (i + 1 < w.size() && f[i] == 0.0) ++i;
  while (i > 0 && f[i] == 0.0) --i;
  return uint32_t(i);
}

TEST(Distribution1D, GuideTableFindsTheBinOfABinarySearch) {
  Pcg32 rng(11);
  for (size_t n : {size_t(1), size_t(2), size_t(7), size_t(64), size_t(1000), size_t(2049)}) {
    // Runs of empty bins and weights spanning twelve orders of magnitude: buckets of the guide
    // table that hold many bins, none, or a bin boundary exactly.
    std::vector<float> w(n);
    for (size_t i = 0; i < n; ++i) w[i] = rng.next_float() < 0.3f ? 0.f : std::exp2(rng.next_float() * 40.f - 20.f);
    w[n / 2] = 1.f;
    Distribution1D d(w);
    std::vector<float> us = {0.f, 0x1.fffffep-1f, 1.f, -0.25f, 0.5f};
    for (int k = 0; k < 20000; ++k) us.push_back(rng.next_float());
    // The guide's bucket edges and the bins' edges, and their float neighbours.
    const uint32_t k = CdfTable::buckets(uint32_t(n));
    for (size_t b = 0; b <= n; ++b)
      for (double edge_d : {double(b) / double(n), double(std::min<size_t>(b, k)) / double(k)}) {
        const float edge = float(edge_d);
        us.insert(us.end(), {edge, std::nextafter(edge, 0.f), std::nextafter(edge, 1.f)});
      }
    for (float u : us) ASSERT_EQ(d.sample_discrete(u), binary_search_bin(w, u)) << "n " << n << " u " << u;
  }
}

TEST(Distribution1D, ContinuousPdfMatchesSampling) {
  Distribution1D d({1.f, 2.f, 1.f, 4.f});
  float pdf = 0;
  uint32_t idx = 0;
  float x = d.sample_continuous(0.99f, &pdf, &idx);
  EXPECT_EQ(idx, 3u);
  EXPECT_FLOAT_EQ(pdf, d.pdf_continuous(x));
  EXPECT_FLOAT_EQ(pdf, 4.f * 4.f / 8.f);
}

TEST(Distribution1D, ZeroWeightsFallBackToUniform) {
  Distribution1D d({0.f, 0.f, std::nanf("")});
  float pmf = 0;
  d.sample_discrete(0.5f, &pmf);
  EXPECT_NEAR(pmf, 1.f / 3.f, 1e-6f);
}

TEST(Distribution2D, PdfIntegratesToOneAndMatchesSamples) {
  std::vector<float> w = {1, 2, 0, 4, 0, 0, 1, 1, 3};
  Distribution2D d(w, 3, 3);
  // Integral of the pdf over the unit square = 1.
  double integral = 0;
  const int res = 300;
  for (int y = 0; y < res; ++y)
    for (int x = 0; x < res; ++x) integral += d.pdf({(x + 0.5f) / res, (y + 0.5f) / res});
  EXPECT_NEAR(integral / (res * res), 1.0, 1e-3);
  Pcg32 rng(5);
  for (int i = 0; i < 1000; ++i) {
    float pdf = 0;
    Vec2 uv = d.sample({rng.next_float(), rng.next_float()}, &pdf);
    EXPECT_GT(pdf, 0.f);
    EXPECT_NEAR(pdf, d.pdf(uv), 1e-4f * pdf);
  }
}

TEST(Hash, PcgIsDeterministic) {
  Pcg32 a(42), b(42);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(a.next_u32(), b.next_u32());
  EXPECT_LT(bits_to_unit_float(0xFFFFFFFFu), 1.f);
}

}  // namespace
}  // namespace tessera
