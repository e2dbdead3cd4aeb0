// The `constant` emitter.
#include "support/chi2.h"
#include "tessera/core/hash.h"
#include "tessera/light/constant.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

TEST(ConstantLight, RadianceAndPdfAreTheSameEverywhere) {
  ConstantLight light(Rgb(0.5f, 1.f, 2.f));
  for (Vec3 d : {Vec3(0, 1, 0), Vec3(0, -1, 0), normalize(Vec3(1, 2, 3))}) {
    EXPECT_EQ(light.le_env(d), Rgb(0.5f, 1.f, 2.f));
    EXPECT_FLOAT_EQ(light.pdf_env(d), 1.f / (4.f * kPi));
  }
  EXPECT_TRUE(light.is_infinite());
  EXPECT_FALSE(light.is_delta());
}

TEST(ConstantLight, SamplesAreUniformOverTheSphere) {
  ConstantLight light(Rgb(1.f));
  auto r = test::chi2_test(
      [&](Vec2 u) {
        LightSample ls;
        if (!light.sample_li(Vec3(0.f), u, ls)) return test::Chi2Sample{Vec3(), 0.f, false};
        EXPECT_EQ(ls.li, Rgb(1.f));
        EXPECT_EQ(ls.dist, kInfinity);
        return test::Chi2Sample{ls.wi, ls.pdf};
      },
      [&](Vec3 w) { return double(light.pdf_env(w)); }, test::Chi2Options{});
  EXPECT_TRUE(r.passed) << r.message;
}

TEST(ConstantLight, IrradianceOnAPlaneIsPiTimesRadiance) {
  ConstantLight light(Rgb(2.f));
  Pcg32 rng(4);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    LightSample ls;
    ASSERT_TRUE(light.sample_li(Vec3(0.f), {rng.next_float(), rng.next_float()}, ls));
    double f = ls.li.g * std::max(0.f, ls.wi.y) / ls.pdf;
    sum += f;
    sum2 += f * f;
  }
  double mean = sum / n, stderr_ = std::sqrt((sum2 / n - mean * mean) / n);
  EXPECT_NEAR(mean, 2.0 * M_PI, 5 * stderr_);
}

TEST(ConstantLight, PowerScalesWithSceneCrossSection) {
  ConstantLight light(Rgb(1.f));
  EXPECT_NEAR(light.power(), 4.f * kPi * kPi, 1e-4f);
  Bounds3 b;
  b.extend(Vec3(0, 0, 0));
  b.extend(Vec3(2, 4, 4));  // diagonal length 6: radius 3
  light.preprocess(b);
  EXPECT_NEAR(light.power(), 4.f * kPi * kPi * 9.f, 1e-3f);
}

}  // namespace
}  // namespace tessera
