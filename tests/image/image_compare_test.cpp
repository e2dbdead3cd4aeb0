#include "tessera/core/hash.h"
#include "tessera/core/ray.h"
#include "tessera/image/image_compare.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace tessera {
namespace {

Image constant_image(int w, int h, Rgb v) {
  Image img(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.set_rgb(x, y, v);
  return img;
}

TEST(ImageCompare, MeansAndErrorsOnKnownValues) {
  Image a = constant_image(4, 2, Rgb(1.f, 2.f, 3.f));
  auto m = channel_means(a);
  EXPECT_DOUBLE_EQ(m[0], 1.0);
  EXPECT_DOUBLE_EQ(m[2], 3.0);

  Image b = constant_image(4, 2, Rgb(1.f, 2.f, 2.f));
  // Only the blue channel differs, by 1, on a reference value of 2: (1 / (4 + 0.01)) / 3 channels.
  EXPECT_NEAR(rel_mse(a, b), (1.0 / (4.0 + 0.01)) / 3.0, 1e-12);
  EXPECT_NEAR(rel_mse(a, b, 0.0), (1.0 / 4.0) / 3.0, 1e-12);
  EXPECT_NEAR(mse(a, b), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(mean_abs_error(a, b), 1.0 / 3.0, 1e-12);
  EXPECT_EQ(rel_mse(a, a), 0.0);

  // The epsilon keeps black reference pixels finite.
  Image black = constant_image(4, 2, Rgb(0.f));
  EXPECT_NEAR(rel_mse(constant_image(4, 2, Rgb(0.1f)), black), 0.01 / 0.01, 1e-6);

  EXPECT_THROW(rel_mse(a, constant_image(2, 4, Rgb(0.f))), std::invalid_argument);
}

TEST(ImageCompare, CountsNonFiniteValues) {
  Image a = constant_image(2, 2, Rgb(1.f));
  a.at(1, 1, 2) = std::nanf("");
  a.at(0, 1, 0) = INFINITY;
  EXPECT_EQ(count_non_finite(a), 2u);
}

TEST(ImageCompare, DownsampleAveragesAndHandlesRaggedEdges) {
  Image a(3, 3, 1);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) a.at(x, y, 0) = float(x + 3 * y);
  Image d = downsample(a, 2);
  ASSERT_EQ(d.width(), 2);
  ASSERT_EQ(d.height(), 2);
  EXPECT_FLOAT_EQ(d.at(0, 0, 0), (0 + 1 + 3 + 4) / 4.f);
  EXPECT_FLOAT_EQ(d.at(1, 0, 0), (2 + 5) / 2.f);
  EXPECT_FLOAT_EQ(d.at(1, 1, 0), 8.f);
  Image v = downsample_variance(constant_image(2, 2, Rgb(4.f)), 2);
  EXPECT_FLOAT_EQ(v.at(0, 0, 0), 1.f);  // mean of 4 values of variance 4
}

// An unbiased noisy image scores mean z^2 ~ 1 against its variance; a biased one does not.
TEST(ImageCompare, ZScoresSeparateNoiseFromBias) {
  const int w = 64, h = 64;
  Image ref = constant_image(w, h, Rgb(0.5f)), var = constant_image(w, h, Rgb(0.01f));
  Image noisy(w, h, 3), biased(w, h, 3);
  Pcg32 rng(17);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        // Box-Muller normal with sigma 0.1.
        float u1 = std::max(rng.next_float(), 1e-7f), u2 = rng.next_float();
        float n = std::sqrt(-2.f * std::log(u1)) * std::cos(2.f * kPi * u2);
        noisy.at(x, y, c) = 0.5f + 0.1f * n;
        biased.at(x, y, c) = 0.55f + 0.1f * n;
      }
  ZScoreStats s = z_score_stats(noisy, ref, var);
  EXPECT_EQ(s.count, size_t(w * h * 3));
  EXPECT_NEAR(s.mean_z2, 1.0, 0.1);
  EXPECT_NEAR(s.mean_z, 0.0, 0.1);
  ZScoreStats b = z_score_stats(biased, ref, var);
  EXPECT_GT(b.mean_z, 0.4);
  EXPECT_GT(b.mean_z2, 1.15);
}

TEST(ImageCompare, CornellReferenceAgainstItself) {
  std::string ref_path = test::shared_path("references/cornell-box/reference.exr");
  std::string var_path = test::shared_path("references/cornell-box/variance.exr");
  TESSERA_REQUIRE_FILE(ref_path);
  Image ref = read_image(ref_path), var = read_image(var_path);
  EXPECT_EQ(rel_mse(ref, ref), 0.0);
  EXPECT_EQ(z_score_stats(ref, ref, var).mean_z2, 0.0);
  // Downsampling keeps the mean.
  auto m0 = channel_means(ref), m1 = channel_means(downsample(ref, 4));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(m0[size_t(c)], m1[size_t(c)], 1e-6);
}

}  // namespace
}  // namespace tessera
