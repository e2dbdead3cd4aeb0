// Adaptive sampling's split of a pass (adaptive.h) on films of known variance: the budget is spent
// exactly, within the cap, in proportion to the square root of the variance, nothing to converged
// pixels, by the neighbours' variance rather than the pixel's own, evenly when nothing is known; and
// which passes may adapt.
#include "tessera/render/adaptive.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

namespace tessera {
namespace {

// A film of `width` x `height` whose pixel (x, y) holds `n` samples alternating mean - d and
// mean + d, d = deviation(x, y): its sample variance is known exactly.
template <typename Deviation>
Film film_with(int width, int height, uint32_t n, float mean, Deviation deviation) {
  Film film({0, 0, width, height}, width, height);
  FilmTile tile({0, 0, width, height});
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (uint32_t i = 0; i < n; ++i) {
        const float d = (i % 2 ? 1.f : -1.f) * deviation(x, y);
        tile.add_sample({x, y}, Rgb(mean + d));
      }
  film.add_tile(tile);
  return film;
}

uint64_t total(const std::vector<uint32_t>& counts) { return std::accumulate(counts.begin(), counts.end(), uint64_t(0)); }

// Left half: deviation 0.1; right half: 0.4, so 16x the variance and 4x the share.
Film two_halves(uint32_t n) {
  return film_with(16, 8, n, 1.f, [](int x, int) { return x < 8 ? 0.1f : 0.4f; });
}

TEST(AllocateSamples, SpendsTheBudgetExactlyWithinTheCap) {
  const Film film = two_halves(16);
  for (uint32_t pass_spp : {1u, 7u, 64u}) {
    const uint64_t budget = uint64_t(pass_spp) * 16 * 8;
    const std::vector<uint32_t> counts = allocate_samples(film, pass_spp, AdaptiveSettings{});
    ASSERT_EQ(counts.size(), 16u * 8u);
    EXPECT_EQ(total(counts), budget) << pass_spp;
    EXPECT_LE(*std::max_element(counts.begin(), counts.end()), 4 * pass_spp) << pass_spp;
  }
}

TEST(AllocateSamples, TotalsFollowTheSquareRootOfTheVariance) {
  const Film film = two_halves(16);
  const std::vector<uint32_t> counts = allocate_samples(film, 64, AdaptiveSettings{});
  // Away from the border (where the 3x3 neighbourhood reaches across): totals 16 + count in 1 : 4.
  for (int y = 0; y < 8; ++y) {
    const double quiet = 16.0 + counts[size_t(y) * 16 + 3], noisy = 16.0 + counts[size_t(y) * 16 + 12];
    EXPECT_NEAR(noisy / quiet, 4.0, 0.15) << "row " << y << ": " << quiet << " and " << noisy;
  }
}

TEST(AllocateSamples, ConvergedPixelsTakeNone) {
  // The left half is nearly noiseless; a small budget all goes right.
  const Film film = film_with(16, 8, 16, 1.f, [](int x, int) { return x < 8 ? 1e-4f : 0.5f; });
  const std::vector<uint32_t> counts = allocate_samples(film, 4, AdaptiveSettings{});
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 6; ++x) EXPECT_EQ(counts[size_t(y) * 16 + x], 0u) << x << "," << y;
    for (int x = 9; x < 16; ++x) EXPECT_GT(counts[size_t(y) * 16 + x], 4u) << x << "," << y;
  }
}

TEST(AllocateSamples, APixelsShareComesFromItsNeighboursNotItsOwnSamples) {
  // One pixel caught a firefly: its neighbours take more samples, it does not (its own samples
  // deciding its count would bias its mean).
  const Film film = film_with(9, 9, 16, 1.f, [](int x, int y) { return x == 4 && y == 4 ? 5.f : 0.05f; });
  const std::vector<uint32_t> counts = allocate_samples(film, 8, AdaptiveSettings{});
  const auto at = [&](int x, int y) { return counts[size_t(y) * 9 + x]; };
  EXPECT_GT(at(3, 4), at(1, 4));
  EXPECT_GT(at(3, 4), at(4, 4));
  EXPECT_EQ(at(4, 4), at(2, 4));  // (the same colour of the checkerboard, both among quiet neighbours)
}

TEST(AllocateSamples, WithoutVarianceEveryPixelTakesThePassesSamples) {
  for (float mean : {0.f, 2.f}) {
    const Film film = film_with(12, 5, 8, mean, [](int, int) { return 0.f; });
    const std::vector<uint32_t> counts = allocate_samples(film, 16, AdaptiveSettings{});
    EXPECT_EQ(counts, std::vector<uint32_t>(12 * 5, 16u)) << mean;
  }
}

TEST(AllocateSamples, TheSameFilmGivesTheSameCounts) {
  const Film film = film_with(24, 16, 9, 0.5f, [](int x, int y) { return 0.01f * float((x * 7 + y * 13) % 17); });
  const auto a = allocate_samples(film, 33, AdaptiveSettings{});
  EXPECT_EQ(a, allocate_samples(film, 33, AdaptiveSettings{}));
  EXPECT_GT(*std::max_element(a.begin(), a.end()), 33u);
  EXPECT_LT(*std::min_element(a.begin(), a.end()), 33u);
}

TEST(AdaptivePass, OnlyAfterAQuarterOfTheBudgetAndEnoughSamplesInEveryPixel) {
  const AdaptiveSettings s;  // 8 samples, a quarter
  EXPECT_FALSE(adaptive_pass(63, 256, 63, s));
  EXPECT_TRUE(adaptive_pass(64, 256, 64, s));
  EXPECT_FALSE(adaptive_pass(127, 256, 7, s));  // (the film after guiding's training passes)
  EXPECT_TRUE(adaptive_pass(127, 256, 8, s));
  EXPECT_FALSE(adaptive_pass(7, 16, 7, s));
}

TEST(PassSamples, UniformAndIndexedByPixel) {
  const PassSamples s = PassSamples::uniform({2, 3, 10, 7}, 5, 9);
  EXPECT_EQ(s.first, std::vector<uint32_t>(32, 5u));
  EXPECT_EQ(s.count, std::vector<uint32_t>(32, 4u));
  EXPECT_EQ(s.index({2, 3}), 0u);
  EXPECT_EQ(s.index({4, 5}), 18u);
}

TEST(PlanPass, UniformUntilAdaptiveThenAllocated) {
  const Film film = two_halves(16);
  const std::vector<uint32_t> taken(16 * 8, 16);
  const AdaptiveSettings s;
  const PassSamples off = plan_pass(film, taken, 16, 16, 64, nullptr);
  EXPECT_EQ(off.count, std::vector<uint32_t>(16 * 8, 16u));
  EXPECT_EQ(off.first, taken);
  const PassSamples on = plan_pass(film, taken, 16, 16, 64, &s);
  EXPECT_EQ(on.count, allocate_samples(film, 16, s));
  EXPECT_EQ(on.first, taken);
  EXPECT_EQ(plan_pass(film, taken, 15, 16, 64, &s).count, off.count);  // begins before a quarter
}

}  // namespace
}  // namespace tessera
