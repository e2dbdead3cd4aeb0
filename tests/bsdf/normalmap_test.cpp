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
    ASSERT_NO_FATAL_FAILURE(test::expect_flat_map_is_nested(*nm, *nested, si, 4));
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

// Tilted by 30 degrees towards azimuth 200 degrees.
const Vec3 kTilted = direction_deg(30.f, 200.f);

TEST(NormalMap, Chi2SamplingMatchesPdfOverATiltedFrame) {
  auto normals = test::solid_rgb_texture(encode(kTilted));
  test::expect_tilted_chi2_passes([&](const Bsdf* nested) { return make_normalmap_bsdf(nested, normals); });
}

TEST(NormalMap, SampleWeightIsEvalOverPdf) {
  auto normals = test::solid_rgb_texture(encode(kTilted));
  test::expect_tilted_weights_are_eval_over_pdf(
      [&](const Bsdf* nested) { return make_normalmap_bsdf(nested, normals); }, 12);
}

// As for bumpmap: a white diffuse about a normal tilted by alpha keeps (1 + cos alpha) / 2.
TEST(NormalMap, WhiteDiffuseAlbedoIsTheClippedLobe) {
  auto diffuse = test::white_diffuse(1.f);
  auto nm = make_normalmap_bsdf(diffuse.get(), test::solid_rgb_texture(encode(kTilted)));
  test::expect_clipped_lobe_albedo(*nm, 200.f, 19, 0.5 * (1.0 + std::cos(30.0 * kPi / 180.0)));
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
        ASSERT_NO_FATAL_FAILURE(test::expect_finite_everywhere(*nm, si, 29, 200, "bad texel or tangent"));
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
