// Homogeneous medium: Beer-Lambert transmittance, and unbiased free-flight sampling with chromatic
// extinction (the expected weights equal the analytic single-scattering and pass-through integrals
// channel by channel).
#include "tessera/render/medium.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

std::unique_ptr<Medium> medium(Rgb sigma_t, Rgb albedo) {
  return make_homogeneous_medium(sigma_t, albedo, make_isotropic_phase());
}

TEST(Homogeneous, TransmittanceIsBeerLambertInWorldUnits) {
  auto m = medium(Rgb(0.5f, 1.f, 2.f), Rgb(0.3f));
  Ray r{Vec3(0.f), Vec3(0.f, 0.f, 3.f)};  // |d| = 3: t = 0.5 is 1.5 world units
  Rgb tr = m->transmittance(r, 0.5f);
  EXPECT_NEAR(tr.r, std::exp(-0.75f), 1e-6f);
  EXPECT_NEAR(tr.g, std::exp(-1.5f), 1e-6f);
  EXPECT_NEAR(tr.b, std::exp(-3.f), 1e-6f);
}

TEST(Homogeneous, InfiniteSegmentWithAClearChannelIsFinite) {
  auto m = medium(Rgb(0.f, 1.f, 0.f), Rgb(0.5f));
  Rgb tr = m->transmittance(Ray{Vec3(0.f), Vec3(1.f, 0.f, 0.f)}, kInfinity);
  EXPECT_EQ(tr.r, 1.f);
  EXPECT_EQ(tr.g, 0.f);
  EXPECT_EQ(tr.b, 1.f);
  MediumSample ms;
  for (float u : {0.1f, 0.5f, 0.9f}) {
    m->sample(Ray{Vec3(0.f), Vec3(1.f, 0.f, 0.f)}, kInfinity, Vec2(u, 0.3f), ms);
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(std::isfinite(ms.weight[c]));
  }
}

// Integrates the sampler over a fine grid of (u.x, u.y): the mean of weight * [scattered] must be
// the probability-weighted single-scattering integral  int_0^d sigma_s exp(-sigma_t s) ds  and the
// mean of weight * [passed] the transmittance exp(-sigma_t d), for every channel.
void expect_unbiased(Rgb sigma_t, Rgb albedo, float dist) {
  auto m = medium(sigma_t, albedo);
  const Ray r{Vec3(0.f), Vec3(0.f, 2.f, 0.f)};
  const float tmax = dist / 2.f;
  const int n = 1500;
  double scatter[3] = {0, 0, 0}, pass[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      MediumSample ms;
      m->sample(r, tmax, Vec2((i + 0.5f) / n, (j + 0.5f) / n), ms);
      for (int c = 0; c < 3; ++c) (ms.scattered ? scatter : pass)[c] += ms.weight[c];
      if (ms.scattered) {
        EXPECT_LT(ms.t, tmax);
      }
    }
  for (int c = 0; c < 3; ++c) {
    const double st = sigma_t[c], ss = sigma_t[c] * albedo[c];
    const double expect_pass = std::exp(-st * dist);
    const double expect_scatter = st > 0 ? ss / st * (1.0 - std::exp(-st * dist)) : 0.0;
    EXPECT_NEAR(pass[c] / (double(n) * n), expect_pass, 2e-3 + 2e-3 * expect_pass) << "channel " << c;
    EXPECT_NEAR(scatter[c] / (double(n) * n), expect_scatter, 2e-3 + 2e-3 * expect_scatter) << "channel " << c;
  }
}

TEST(Homogeneous, FreeFlightSamplingIsUnbiasedPerChannel) {
  expect_unbiased(Rgb(1.f), Rgb(0.8f), 1.f);
  expect_unbiased(Rgb(0.2f, 1.f, 4.f), Rgb(0.9f, 0.5f, 0.1f), 1.3f);
  expect_unbiased(Rgb(0.f, 2.f, 0.5f), Rgb(1.f), 0.7f);
}

TEST(Homogeneous, PureAbsorberNeverScattersAndWeighsByTransmittance) {
  // staircase2's glass: sigma_s = 0. Every sample passes with weight exactly exp(-sigma_t d).
  auto m = medium(Rgb(0.5f, 0.2f, 0.4f), Rgb(0.f));
  EXPECT_TRUE(m->absorbing_only());
  const Ray r{Vec3(0.f), Vec3(1.f, 0.f, 0.f)};
  for (float u : {0.f, 0.3f, 0.999f}) {
    MediumSample ms;
    m->sample(r, 2.f, Vec2(u, 1.f - u), ms);
    EXPECT_FALSE(ms.scattered);
    EXPECT_FLOAT_EQ(ms.weight.r, std::exp(-1.f));
    EXPECT_FLOAT_EQ(ms.weight.g, std::exp(-0.4f));
    EXPECT_FLOAT_EQ(ms.weight.b, std::exp(-0.8f));
  }
}

}  // namespace
}  // namespace tessera
