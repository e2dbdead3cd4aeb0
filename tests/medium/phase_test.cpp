// Phase functions: chi-square of sample() against pdf(), normalisation, and eval == pdf.
#include "support/chi2.h"
#include "tessera/core/frame.h"
#include "tessera/render/medium.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using test::Chi2Options;
using test::Chi2Sample;

// wo as the chi-square harness sees it: the harness bins directions about +z, so a tilted wo
// checks that the lobe follows -wo rather than a fixed axis.
const Vec3 kWo = normalize(Vec3(0.3f, -0.5f, 0.8f));

void expect_chi2(const PhaseFunction& phase, const std::string& name, int test_count) {
  Chi2Options opt;
  opt.name = name;
  opt.test_count = test_count;
  auto r = test::chi2_test(
      [&](Vec2 u) {
        Vec3 wi;
        float pdf = 0.f;
        float w = phase.sample(kWo, u, wi, pdf);
        return Chi2Sample{wi, pdf, w > 0.f};
      },
      [&](Vec3 w) { return double(phase.pdf(kWo, w)); }, opt);
  EXPECT_TRUE(r.passed) << r.message;
}

TEST(Phase, IsotropicChiSquare) { expect_chi2(*make_isotropic_phase(), "isotropic", 1); }

TEST(Phase, HenyeyGreensteinChiSquare) {
  const float gs[] = {-0.7f, -0.2f, 0.0005f, 0.3f, 0.8f, 0.95f};
  for (float g : gs) expect_chi2(*make_hg_phase(g), "hg g=" + std::to_string(g), 6);
}

TEST(Phase, HenyeyGreensteinMeanCosineIsG) {
  // The mean cosine of the scattering angle is g by definition: integrate cos * p numerically.
  for (float g : {-0.5f, 0.f, 0.4f, 0.9f}) {
    auto phase = make_hg_phase(g);
    const int n = 20000;
    double mean = 0, norm = 0;
    for (int i = 0; i < n; ++i) {
      double c = -1.0 + (i + 0.5) * 2.0 / n;  // cos between -wo and wi
      Vec3 forward = -kWo;
      Frame f(forward);
      Vec3 wi = f.to_world(Vec3(float(std::sqrt(1 - c * c)), 0.f, float(c)));
      double p = phase->eval(kWo, wi) * 2.0 * 3.14159265358979 * (2.0 / n);
      norm += p;
      mean += c * p;
    }
    EXPECT_NEAR(norm, 1.0, 2e-3) << "g=" << g;
    EXPECT_NEAR(mean, g, 3e-3) << "g=" << g;
  }
}

TEST(Phase, ForwardScatteringFollowsTheRayDirection) {
  // g > 0: the most likely wi is the ray's own direction, -wo.
  auto phase = make_hg_phase(0.8f);
  EXPECT_GT(phase->eval(kWo, -kWo), 10.f * phase->eval(kWo, kWo));
}

}  // namespace
}  // namespace tessera
