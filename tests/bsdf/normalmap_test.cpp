// normalmap (Mitsuba 3): a flat map (0.5, 0.5, 1) is exactly the nested BSDF; a constant map
// tilts the normal to normalize(2 rgb - 1) in the (dp/du, bitangent, n) tangent space; sample()
// matches pdf() (chi-square); weight == eval / pdf; white-diffuse albedo is the clipped lobe;
// bad texels and degenerate tangents never give NaN.
#include "bsdf/perturbed_test_util.h"

#include "bsdf/bsdf_test_util.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace tessera {
namespace {

using test::direction_deg;

/// The colour that encodes the unit tangent-space normal `n`.
Rgb encode(Vec3 n) { return Rgb(0.5f * (n.x + 1.f), 0.5f * (n.y + 1.f), 0.5f * (n.z + 1.f)); }

TEST(NormalMap, FlatMapIsExactlyTheNestedBsdf) {
  SurfaceInteraction si = test::flat_si();
  si.shading = Frame(normalize(Vec3(-0.2f, 0.4f, 1.f)));
  si.dpdu = Vec3(0.3f, 0.9f, 0.f);
  auto diffuse = test::white_diffuse(0.6f);
  auto gold = test::rough_gold();
  for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
    auto nm = make_normalmap_bsdf(nested, test::solid_rgb_texture(Rgb(0.5f, 0.5f, 1.f)));
    Pcg32 rng(4);
    for (int i = 0; i < 500; ++i) {
      Vec3 wo = direction_deg(85.f * rng.next_float(), 360.f * rng.next_float());
      Vec3 wi = direction_deg(85.f * rng.next_float(), 360.f * rng.next_float());
      EXPECT_EQ(nm->eval(si, wo, wi), nested->eval(si, wo, wi));
      EXPECT_EQ(nm->pdf(si, wo, wi), nested->pdf(si, wo, wi));
      float u1 = rng.next_float();
      Vec2 u2(rng.next_float(), rng.next_float());
      BsdfSample a, b;
      bool ok_a = nm->sample(si, wo, u1, u2, a), ok_b = nested->sample(si, wo, u1, u2, b);
      ASSERT_EQ(ok_a, ok_b);
      if (!ok_a) continue;
      EXPECT_EQ(a.wi, b.wi);
      EXPECT_EQ(a.pdf, b.pdf);
      EXPECT_EQ(a.weight, b.weight);
    }
  }
}

TEST(NormalMap, NormalIsReadInTheTangentSpace) {
  auto diffuse = test::white_diffuse();
  const Vec3 tangent_n = normalize(Vec3(0.4f, -0.2f, 1.f));
  auto nm = make_normalmap_bsdf(diffuse.get(), test::solid_rgb_texture(encode(tangent_n)));
  struct Case {
    Vec3 dpdu, expected;
  };
  // dp/du along +x: tangent space = world; along +y: x -> +y, y -> -x (bitangent n x dp/du).
  const Case cases[] = {{{2, 0, 0}, tangent_n}, {{0, 0.5f, 0}, {-tangent_n.y, tangent_n.x, tangent_n.z}},
                        {{1, 0, 0.7f}, tangent_n}};  // dp/du's normal component is projected away
  for (const Case& c : cases) {
    SurfaceInteraction si = test::flat_si();
    si.dpdu = c.dpdu;
    Vec3 n = c.expected;
    Pcg32 rng(6);
    for (int i = 0; i < 200; ++i) {
      Vec3 wi = direction_deg(89.f * rng.next_float(), 360.f * rng.next_float());
      // The 8-bit-free float texture holds the normal to float precision.
      EXPECT_NEAR(nm->eval(si, n, wi).g, std::max(0.f, dot(wi, n)) * kInvPi, 2e-5f);
    }
  }
}

const float kAngles[] = {0.f, 30.f, 60.f, 80.f};
// Tilted by 30 degrees towards azimuth 200 degrees.
const Vec3 kTilted = direction_deg(30.f, 200.f);

TEST(NormalMap, Chi2SamplingMatchesPdfOverATiltedFrame) {
  auto diffuse = test::white_diffuse(0.8f);
  auto gold = test::rough_gold(0.3f);
  auto normals = test::solid_rgb_texture(encode(kTilted));
  SurfaceInteraction si = test::flat_si();
  const int tests = 2 * int(std::size(kAngles));
  for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
    auto nm = make_normalmap_bsdf(nested, normals);
    for (float deg : kAngles) {
      test::Chi2Options o;
      o.test_count = tests;
      o.sample_count = 300000;
      o.name = std::string(nested == diffuse.get() ? "diffuse" : "roughconductor") + " theta_o " + std::to_string(deg);
      if (nested == gold.get()) {
        o.cos_theta_bins = 100;
        o.phi_bins = 200;
        o.sample_count = 1000000;
      }
      auto r = test::bsdf_chi2_test(*nm, si, direction_deg(deg, 190.f), o);
      EXPECT_TRUE(r.passed) << r.message;
      EXPECT_GT(r.valid_samples, o.sample_count / 2) << o.name;
    }
  }
}

TEST(NormalMap, SampleWeightIsEvalOverPdf) {
  auto normals = test::solid_rgb_texture(encode(kTilted));
  SurfaceInteraction si = test::flat_si();
  auto diffuse = test::white_diffuse(0.8f);
  auto gold = test::rough_gold(0.3f);
  for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
    auto nm = make_normalmap_bsdf(nested, normals);
    Pcg32 rng(12);
    int checked = 0;
    for (float deg : kAngles) {
      Vec3 wo = direction_deg(deg, 190.f);
      for (int i = 0; i < 300; ++i) {
        BsdfSample bs;
        if (!nm->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
        ASSERT_GT(bs.wi.z, 0.f);
        float pdf = nm->pdf(si, wo, bs.wi);
        ASSERT_GT(pdf, 0.f);
        EXPECT_NEAR(bs.pdf, pdf, 1e-3f * pdf);
        Rgb ratio = nm->eval(si, wo, bs.wi) / pdf;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], ratio[c], 2e-3f * ratio[c] + 1e-6f);
        ++checked;
      }
    }
    EXPECT_GT(checked, 600);
  }
}

// As for bumpmap: a white diffuse about a normal tilted by alpha keeps (1 + cos alpha) / 2.
TEST(NormalMap, WhiteDiffuseAlbedoIsTheClippedLobe) {
  auto diffuse = test::white_diffuse(1.f);
  auto nm = make_normalmap_bsdf(diffuse.get(), test::solid_rgb_texture(encode(kTilted)));
  SurfaceInteraction si = test::flat_si();
  const double expected = 0.5 * (1.0 + std::cos(30.0 * kPi / 180.0));
  for (float deg : kAngles) {
    double mean, err;
    test::directional_albedo(*nm, si, direction_deg(deg, 200.f), 200000, 19, mean, err);
    EXPECT_NEAR(mean, expected, 4 * err + 1e-3) << deg;
    EXPECT_LE(mean, 1.0 + 4 * err);
  }
}

TEST(NormalMap, BadTexelsAndTangentsNeverGiveNaN) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  auto diffuse = test::white_diffuse(0.8f);
  auto gold = test::rough_gold(0.3f);
  for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
    const Rgb texels[] = {Rgb(nan, 0.5f, 1.f), Rgb(inf, 0.5f, 1.f), Rgb(0.5f, 0.5f, 0.5f),  // zero normal
                          Rgb(0.5f, 0.5f, 0.f), Rgb(1e38f, 1e38f, 1e38f), encode(kTilted)};
    for (Rgb t : texels) {
      auto nm = make_normalmap_bsdf(nested, test::solid_rgb_texture(t));
      for (Vec3 dpdu : {Vec3(0.f), Vec3(0.f, 0.f, 1.f), Vec3(nan, 0.f, 0.f), Vec3(1e30f, 1e30f, 0.f)}) {
        SurfaceInteraction si = test::flat_si();
        si.dpdu = dpdu;
        Pcg32 rng(29);
        for (int i = 0; i < 200; ++i) {
          Vec3 wo = direction_deg(180.f * rng.next_float(), 360.f * rng.next_float());
          Vec3 wi = direction_deg(180.f * rng.next_float(), 360.f * rng.next_float());
          ASSERT_TRUE(nm->eval(si, wo, wi).is_finite());
          float pdf = nm->pdf(si, wo, wi);
          ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0.f);
          BsdfSample bs;
          if (nm->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) {
            ASSERT_TRUE(is_finite(bs.wi) && bs.weight.is_finite() && std::isfinite(bs.pdf));
            ASSERT_NEAR(length(bs.wi), 1.f, 1e-4f);
          }
        }
      }
    }
    // A zero normal (grey texel) falls back to the shape's frame.
    auto grey = make_normalmap_bsdf(nested, test::solid_rgb_texture(Rgb(0.5f)));
    SurfaceInteraction si = test::flat_si();
    Vec3 wo = direction_deg(30.f, 10.f), wi = direction_deg(50.f, 200.f);
    EXPECT_EQ(grey->eval(si, wo, wi), nested->eval(si, wo, wi));
  }
}

TEST(NormalMap, ForwardsDelta) {
  auto mirror = make_conductor_bsdf(*lookup_metal("Ag"), std::make_shared<ConstantTexture>(Rgb(1.f)));
  auto nm = make_normalmap_bsdf(mirror.get(), test::solid_rgb_texture(encode(kTilted)));
  EXPECT_TRUE(nm->is_delta());
  EXPECT_FALSE(nm->has_opacity());
  // The mirror reflects about the mapped normal.
  BsdfSample bs;
  Vec3 wo = kTilted;
  ASSERT_TRUE(nm->sample(test::flat_si(), wo, 0.5f, {0.5f, 0.5f}, bs));
  EXPECT_NEAR(length(bs.wi - kTilted), 0.f, 1e-5f);
}

}  // namespace
}  // namespace tessera
