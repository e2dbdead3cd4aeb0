// Path guiding's mixture of BSDF and guided sampling (render/guided_sampling.h): its samples follow
// its pdf (chi-square) for diffuse and rough metal BSDFs and a trained guide, its weight is
// eval / pdf, a delta lobe keeps the BSDF's weight for the probability of choosing the BSDF, a
// fraction of one is the BSDF's own sampling, and only lobes rough enough are guided.
#include "tessera/render/guided_sampling.h"

#include "support/chi2.h"
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/dielectric.h"
#include "tessera/bsdf/diffuse.h"
#include "tessera/bsdf/roughplastic.h"
#include "tessera/core/hash.h"
#include "tessera/core/sampling.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

// A guide that learned light from a lobe around `axis` (and a little from everywhere).
DirectionalTree guide_towards(Vec3 axis) {
  DirectionalTree tree;
  Pcg32 rng(17);
  for (int it = 0; it < 3; ++it) {
    for (int k = 0; k < 100000; ++k) {
      const Vec3 d = square_to_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
      tree.record(d, 4.f * kPi * (20.f * std::pow(std::max(0.f, dot(d, axis)), 20.f) + 0.1f), rng.next_float());
    }
    tree.build();
    if (it < 2) tree = tree.refined(0.01);
  }
  return tree;
}

std::shared_ptr<Texture> constant(float c) { return std::make_shared<ConstantTexture>(Rgb(c)); }

TEST(GuidedSampling, Chi2MixtureMatchesItsPdf) {
  const DirectionalTree guide = guide_towards(normalize(Vec3(-0.4f, 0.2f, 0.6f)));
  const std::shared_ptr<Bsdf> bsdfs[] = {
      make_diffuse_bsdf(std::make_shared<ConstantTexture>(Rgb(0.5f))),
      make_roughconductor_bsdf(MicrofacetType::Ggx, constant(0.2f), nullptr, *lookup_metal("Au"), constant(1.f))};
  const Vec3 wo = normalize(Vec3(0.5f, -0.2f, 0.6f));
  const SurfaceInteraction si;
  test::Chi2Options o;
  o.test_count = 4;
  o.sample_count = 1000000;
  o.cos_theta_bins = 64;
  o.phi_bins = 128;
  o.integration_resolution = 16;
  for (const auto& bsdf : bsdfs)
    for (float fraction : {0.5f, 0.2f}) {
      o.name = "guided mixture, fraction " + std::to_string(fraction);
      auto r = test::chi2_test([&](Vec2 u, float u_lobe) {
        BsdfSample bs;
        if (!sample_guided(*bsdf, si, wo, guide, fraction, u_lobe, u, bs)) return test::Chi2Sample{Vec3(), 0.f, false};
        return test::Chi2Sample{bs.wi, bs.pdf};
      }, [&](Vec3 wi) { return double(guided_pdf(*bsdf, si, wo, wi, guide, fraction)); }, o);
      EXPECT_TRUE(r.passed) << r.message;
    }
}

TEST(GuidedSampling, WeightIsEvalOverTheMixturePdf) {
  const DirectionalTree guide = guide_towards(normalize(Vec3(0.1f, 0.3f, 0.9f)));
  const auto bsdf = make_roughconductor_bsdf(MicrofacetType::Ggx, constant(0.3f), nullptr, *lookup_metal("Cu"), constant(1.f));
  const Vec3 wo = normalize(Vec3(-0.3f, 0.1f, 0.8f));
  const SurfaceInteraction si;
  Pcg32 rng(3);
  int guided_below = 0;
  for (int k = 0; k < 20000; ++k) {
    BsdfSample bs;
    if (!sample_guided(*bsdf, si, wo, guide, 0.4f, rng.next_float(), Vec2(rng.next_float(), rng.next_float()), bs))
      continue;
    const float pdf = guided_pdf(*bsdf, si, wo, bs.wi, guide, 0.4f);
    ASSERT_NEAR(bs.pdf, pdf, 1e-4f * pdf);
    const Rgb expected = bsdf->eval(si, wo, bs.wi) * (1.f / pdf);
    ASSERT_NEAR(bs.weight.r, expected.r, 1e-4f * std::max(1.f, expected.r));
    guided_below += bs.wi.z <= 0.f && bs.weight.is_black();
  }
  EXPECT_GT(guided_below, 0) << "the guide also proposes directions the BSDF cannot use (weight 0)";
}

TEST(GuidedSampling, ADeltaLobeKeepsTheBsdfWeightOverTheChoice) {
  const DirectionalTree guide = guide_towards(Vec3(0.f, 0.f, 1.f));
  const auto glass = make_dielectric_bsdf(1.5f, constant(1.f), constant(1.f));
  const Vec3 wo = normalize(Vec3(0.3f, 0.f, 0.9f));
  const SurfaceInteraction si;
  BsdfSample plain, guided;
  ASSERT_TRUE(glass->sample(si, wo, 0.1f, Vec2(0.3f, 0.7f), plain));
  ASSERT_TRUE(sample_guided(*glass, si, wo, guide, 0.5f, 0.05f, Vec2(0.3f, 0.7f), guided));  // 0.05 / 0.5 = 0.1
  EXPECT_TRUE(guided.delta);
  EXPECT_EQ(guided.wi, plain.wi);
  EXPECT_FLOAT_EQ(guided.weight.g, plain.weight.g / 0.5f);
  EXPECT_FLOAT_EQ(guided.pdf, plain.pdf * 0.5f);
}

TEST(GuidedSampling, AFractionOfOneIsTheBsdfsOwnSampling) {
  // A leaf that learned the guide does not help samples as the unguided path tracer does, bit for
  // bit, and its pdf is the BSDF's; only the parts (for the fraction's loss and the roulette) ask
  // the guide.
  const DirectionalTree guide = guide_towards(normalize(Vec3(0.2f, -0.3f, 0.9f)));
  const auto plastic = make_roughplastic_bsdf(MicrofacetType::Ggx, 0.4f, 1.5f, constant(0.5f), constant(1.f), false);
  const Vec3 wo = normalize(Vec3(0.4f, 0.1f, 0.7f));
  const SurfaceInteraction si;
  Pcg32 rng(9);
  for (int k = 0; k < 2000; ++k) {
    const float u_lobe = rng.next_float();
    const Vec2 u(rng.next_float(), rng.next_float());
    BsdfSample plain, guided;
    MixturePdfs parts;
    const bool sampled = plastic->sample(si, wo, u_lobe, u, plain);
    ASSERT_EQ(sample_guided(*plastic, si, wo, guide, 1.f, u_lobe, u, guided, &parts), sampled);
    if (!sampled) continue;
    ASSERT_EQ(guided.wi, plain.wi);
    ASSERT_EQ(guided.pdf, plain.pdf);
    ASSERT_EQ(guided.weight.g, plain.weight.g);
    ASSERT_EQ(guided_pdf(*plastic, si, wo, guided.wi, guide, 1.f), plastic->pdf(si, wo, guided.wi));
    ASSERT_EQ(parts.guide, guide.pdf_at(parts.square));
    ASSERT_GT(parts.guide, 0.f);
  }
}

TEST(GuidedSampling, OnlyLobesRoughEnoughAreGuided) {
  const SurfaceInteraction si;
  const auto metal = [](float alpha) {
    return make_roughconductor_bsdf(MicrofacetType::Ggx, constant(alpha), nullptr, *lookup_metal("Au"), constant(1.f));
  };
  EXPECT_TRUE(guides_lobe(*make_diffuse_bsdf(constant(0.5f)), si));
  EXPECT_TRUE(guides_lobe(*metal(0.5f), si));
  EXPECT_TRUE(guides_lobe(*metal(kMinGuidedRoughness), si));
  EXPECT_FALSE(guides_lobe(*metal(0.25f), si)) << "veach-mis's roughest plate: the BSDF samples it alone";
  EXPECT_FALSE(guides_lobe(*metal(0.01f), si));
  EXPECT_FALSE(guides_lobe(*make_dielectric_bsdf(1.5f, constant(1.f), constant(1.f)), si));
  // A glossy coat over a diffuse base: the base is what the guide helps.
  EXPECT_TRUE(guides_lobe(*make_roughplastic_bsdf(MicrofacetType::Ggx, 0.05f, 1.5f, constant(0.5f), constant(1.f), false), si));
}

}  // namespace
}  // namespace tessera
