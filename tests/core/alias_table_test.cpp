// Alias table: exact pmfs, chi-square of its samples, degenerate weights, the remapped number.
#include "tessera/core/alias_table.h"
#include "tessera/core/hash.h"
#include "support/discrete_chi2.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

std::vector<float> test_weights() {
  // Spread over six decades, with zeros, a negative and a NaN (both count as 0).
  std::vector<float> w;
  Pcg32 rng(7);
  for (int i = 0; i < 200; ++i) w.push_back(std::pow(10.f, 6.f * rng.next_float() - 3.f));
  w[3] = 0.f;
  w[17] = -1.f;
  w[50] = std::nanf("");
  w[199] = 0.f;
  return w;
}

TEST(AliasTable, PmfIsTheNormalisedWeight) {
  auto w = test_weights();
  AliasTable t(w);
  double sum = 0;
  for (float x : w) sum += (std::isfinite(x) && x > 0.f) ? double(x) : 0.0;
  EXPECT_DOUBLE_EQ(t.total(), sum);
  ASSERT_EQ(t.size(), w.size());
  double pmf_sum = 0;
  for (uint32_t i = 0; i < w.size(); ++i) {
    double expected = (std::isfinite(w[i]) && w[i] > 0.f) ? double(w[i]) / sum : 0.0;
    EXPECT_EQ(t.pmf(i), float(expected)) << i;
    pmf_sum += t.pmf(i);
  }
  EXPECT_NEAR(pmf_sum, 1.0, 1e-5);
  EXPECT_EQ(t.pmf(uint32_t(w.size())), 0.f);
}

// Wide weights (six decades, as light powers) and moderate ones (every bin well populated, so a
// small error in the table's split shows).
void check_samples(const std::vector<float>& w, uint64_t seed) {
  AliasTable t(w);
  std::vector<uint64_t> counts(w.size(), 0);
  std::vector<double> probs(w.size());
  for (uint32_t i = 0; i < w.size(); ++i) probs[i] = t.pmf(i);
  Pcg32 rng(seed);
  double u_sum = 0;
  const int n = 1000000;
  for (int k = 0; k < n; ++k) {
    float pmf = 0.f, u_rest = -1.f;
    uint32_t i = t.sample(rng.next_float(), &pmf, &u_rest);
    ASSERT_LT(i, w.size());
    ASSERT_EQ(pmf, t.pmf(i));
    ASSERT_GE(u_rest, 0.f);
    ASSERT_LT(u_rest, 1.f);
    u_sum += u_rest;
    ++counts[i];
  }
  auto r = test::discrete_chi2(counts, probs, 0, 0.0, 0.01, 2);
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_NEAR(u_sum / n, 0.5, 0.002);  // the remapped number is uniform enough to reuse
}

TEST(AliasTable, SamplesFollowThePmf) {
  check_samples(test_weights(), 12);
  std::vector<float> moderate;
  Pcg32 rng(8);
  for (int i = 0; i < 64; ++i) moderate.push_back(0.5f + 1.5f * rng.next_float());
  check_samples(moderate, 13);
}

TEST(AliasTable, DegenerateWeights) {
  AliasTable empty(std::vector<float>{});
  float pmf = 1.f;
  EXPECT_EQ(empty.sample(0.5f, &pmf), 0u);
  EXPECT_EQ(pmf, 0.f);

  AliasTable zeros(std::vector<float>(4, 0.f));  // uniform fallback, as Distribution1D
  for (uint32_t i = 0; i < 4; ++i) EXPECT_EQ(zeros.pmf(i), 0.25f);
  EXPECT_EQ(zeros.sample(0.9f), 3u);

  AliasTable one_hot({0.f, 0.f, 5.f, 0.f});
  for (float u : {0.f, 0.1f, 0.5f, 0.74f, 0.99f, 0x1.fffffep-1f}) {
    EXPECT_EQ(one_hot.sample(u, &pmf), 2u) << u;
    EXPECT_EQ(pmf, 1.f);
  }
}

}  // namespace
}  // namespace tessera
