// diffuse and twosided: chi-square tests of sample() against pdf(), and the values of eval().
#include "tessera/bsdf/diffuse.h"
#include "tessera/core/frame.h"
#include "tessera/core/hash.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace tessera {
namespace {

using test::Chi2Options;
using test::Chi2Sample;

std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }

Chi2Sample sample_bsdf(const Bsdf& bsdf, Vec3 wo, Vec2 u, float u1) {
  SurfaceInteraction si;
  BsdfSample bs;
  if (!bsdf.sample(si, wo, u1, u, bs)) return {Vec3(), 0.f, false};
  return {bs.wi, bs.pdf, true};
}

double bsdf_pdf(const Bsdf& bsdf, Vec3 wo, Vec3 wi) {
  SurfaceInteraction si;
  return bsdf.pdf(si, wo, wi);
}

const Vec3 kWoFront[] = {normalize(Vec3(0.f, 0.f, 1.f)), normalize(Vec3(0.6f, -0.3f, 0.5f)),
                         normalize(Vec3(-0.9f, 0.1f, 0.05f))};

TEST(Diffuse, Chi2SamplingMatchesPdf) {
  auto bsdf = make_diffuse_bsdf(constant(Rgb(0.5f)));
  Chi2Options o;
  o.test_count = 3;
  o.name = "diffuse";
  for (Vec3 wo : kWoFront) {
    auto r = test::chi2_test(
        test::Chi2Sampler3([&](Vec2 u, float u1) { return sample_bsdf(*bsdf, wo, u, u1); }),
        [&](Vec3 wi) { return bsdf_pdf(*bsdf, wo, wi); }, o);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2);
  }
}

TEST(Diffuse, EvalIsAlbedoOverPiTimesCosineAndOneSided) {
  Rgb albedo(0.2f, 0.5f, 0.8f);
  auto bsdf = make_diffuse_bsdf(constant(albedo));
  SurfaceInteraction si;
  Vec3 wo = normalize(Vec3(0.3f, 0.2f, 0.9f)), wi = normalize(Vec3(-0.5f, 0.1f, 0.6f));
  Rgb f = bsdf->eval(si, wo, wi);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(f[c], albedo[c] * wi.z / kPi, 1e-6f);
  EXPECT_NEAR(bsdf->pdf(si, wo, wi), wi.z / kPi, 1e-6f);
  // One-sided: nothing below the surface, nothing seen from below.
  EXPECT_TRUE(bsdf->eval(si, wo, Vec3(wi.x, wi.y, -wi.z)).is_black());
  EXPECT_TRUE(bsdf->eval(si, Vec3(wo.x, wo.y, -wo.z), wi).is_black());
  EXPECT_EQ(bsdf->pdf(si, Vec3(wo.x, wo.y, -wo.z), wi), 0.f);
  BsdfSample bs;
  EXPECT_FALSE(bsdf->sample(si, Vec3(wo.x, wo.y, -wo.z), 0.5f, {0.3f, 0.7f}, bs));
  EXPECT_FALSE(bsdf->is_delta());
}

// sample() weight must equal eval / pdf (the estimator the integrator relies on), and the
// sampled directions' average weight is the albedo (energy conservation, exactly for Lambert).
TEST(Diffuse, SampleWeightIsEvalOverPdf) {
  Rgb albedo(0.25f, 0.5f, 0.75f);
  auto bsdf = make_diffuse_bsdf(constant(albedo));
  SurfaceInteraction si;
  Vec3 wo = normalize(Vec3(0.1f, 0.4f, 0.7f));
  Pcg32 rng(3);
  for (int i = 0; i < 1000; ++i) {
    BsdfSample bs;
    if (!bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
    EXPECT_GT(bs.wi.z, 0.f);
    EXPECT_NEAR(bs.pdf, bsdf->pdf(si, wo, bs.wi), 1e-5f);
    Rgb ratio = bsdf->eval(si, wo, bs.wi) / bs.pdf;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], ratio[c], 1e-4f);
  }
}

TEST(TwoSided, Chi2SamplingBothSides) {
  auto front = make_diffuse_bsdf(constant(Rgb(0.5f)));
  auto back = make_diffuse_bsdf(constant(Rgb(0.3f)));
  auto single = make_twosided_bsdf(front.get(), nullptr);
  auto pair = make_twosided_bsdf(front.get(), back.get());
  Chi2Options o;
  o.test_count = 12;
  o.name = "twosided";
  for (const Bsdf* b : {single.get(), pair.get()}) {
    for (Vec3 w : kWoFront) {
      for (float sign : {1.f, -1.f}) {
        Vec3 wo(w.x, w.y, sign * w.z);
        auto r = test::chi2_test(
            test::Chi2Sampler3([&](Vec2 u, float u1) { return sample_bsdf(*b, wo, u, u1); }),
            [&](Vec3 wi) { return bsdf_pdf(*b, wo, wi); }, o);
        EXPECT_TRUE(r.passed) << "wo.z sign " << sign << "\n" << r.message;
        EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2);
      }
    }
  }
}

TEST(TwoSided, BackUsesMirroredDirectionsAndBackBsdf) {
  auto front = make_diffuse_bsdf(constant(Rgb(0.6f)));
  auto back = make_diffuse_bsdf(constant(Rgb(0.2f)));
  auto single = make_twosided_bsdf(front.get(), nullptr);
  auto pair = make_twosided_bsdf(front.get(), back.get());
  SurfaceInteraction si;
  Vec3 wo = normalize(Vec3(0.3f, 0.2f, 0.9f)), wi = normalize(Vec3(-0.5f, 0.1f, 0.6f));
  Vec3 wo_b(wo.x, wo.y, -wo.z), wi_b(wi.x, wi.y, -wi.z);
  // Front side: the front BSDF.
  EXPECT_NEAR(single->eval(si, wo, wi).r, 0.6f * wi.z / kPi, 1e-6f);
  // Back side: same value when mirrored (single), the back BSDF's value (pair).
  EXPECT_NEAR(single->eval(si, wo_b, wi_b).r, 0.6f * wi.z / kPi, 1e-6f);
  EXPECT_NEAR(pair->eval(si, wo_b, wi_b).r, 0.2f * wi.z / kPi, 1e-6f);
  EXPECT_NEAR(pair->pdf(si, wo_b, wi_b), wi.z / kPi, 1e-6f);
  // Still no transmission.
  EXPECT_TRUE(single->eval(si, wo_b, wi).is_black());
  EXPECT_TRUE(single->eval(si, wo, wi_b).is_black());
  EXPECT_EQ(single->pdf(si, wo_b, wi), 0.f);
  BsdfSample bs;
  ASSERT_TRUE(pair->sample(si, wo_b, 0.5f, {0.3f, 0.6f}, bs));
  EXPECT_LT(bs.wi.z, 0.f);
  EXPECT_NEAR(bs.weight.r, 0.2f, 1e-6f);
}

}  // namespace
}  // namespace tessera
