// phong (Mitsuba 0.6's modified Phong): chi-square of sample() against pdf() for several exponents
// and incident angles, sample weights, white-furnace albedo, the lobe's normalisation and the lobe
// choice probability, and loading from 0.6 XML (including the energy-conservation rescaling).
#include "tessera/bsdf/roughdiffuse.h"
#include "tessera/core/frame.h"
#include "tessera/core/hash.h"
#include "tessera/scene/load_context.h"
#include "support/chi2.h"
#include "bsdf/bsdf_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace tessera {
namespace {

using test::Chi2Options;
using test::Chi2Sample;

std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }

std::shared_ptr<Bsdf> phong(Rgb kd, Rgb ks, float n) {
  auto d = constant(kd), s = constant(ks);
  float w = phong_specular_sampling_weight(*d, *s);
  return make_phong_bsdf(d, s, constant(Rgb(n)), w);
}

using test::direction_deg;

const Vec3 kWo[] = {direction_deg(0.f, 0.f), direction_deg(40.f, 30.f), direction_deg(75.f, 200.f), direction_deg(89.f, 100.f)};

TEST(Phong, Chi2SamplingMatchesPdf) {
  const float exponents[] = {1.f, 10.f, 100.f};
  Chi2Options o;
  o.test_count = 3 * 4;
  o.sample_count = 300000;
  o.name = "phong";
  for (float n : exponents) {
    // Diffuse and specular equally likely, so both lobes are exercised.
    auto bsdf = phong(Rgb(0.4f), Rgb(0.4f), n);
    for (Vec3 wo : kWo) {
      SurfaceInteraction si;
      auto r = test::bsdf_chi2_test(*bsdf, si, wo, o);
      EXPECT_TRUE(r.passed) << "exponent " << n << " wo.z " << wo.z << "\n" << r.message;
      // Lobe samples below the horizon are rejected, so the pdf integrates to <= 1.
      EXPECT_LE(r.pdf_integral, 1.0 + 1e-2);
      EXPECT_GT(r.pdf_integral, 0.5);
    }
  }
}

TEST(Phong, SampleWeightIsEvalOverPdf) {
  Pcg32 rng(9);
  for (float n : {2.f, 30.f, 400.f}) {
    auto bsdf = phong(Rgb(0.5f, 0.3f, 0.1f), Rgb(0.1f, 0.2f, 0.3f), n);
    SurfaceInteraction si;
    for (Vec3 wo : kWo) {
      for (int i = 0; i < 300; ++i) {
        BsdfSample bs;
        if (!bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
        EXPECT_GT(bs.wi.z, 0.f);
        EXPECT_FALSE(bs.delta);
        EXPECT_NEAR(bs.pdf, bsdf->pdf(si, wo, bs.wi), 1e-4f * std::max(1.f, bs.pdf));
        Rgb ratio = bsdf->eval(si, wo, bs.wi) / bs.pdf;  // eval includes |cos|
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], ratio[c], 1e-4f * std::max(1.f, ratio[c]));
      }
    }
    BsdfSample bs;
    EXPECT_FALSE(bsdf->sample(si, Vec3(0.f, 0.f, -1.f), 0.5f, {0.5f, 0.5f}, bs));
    EXPECT_TRUE(bsdf->eval(si, direction_deg(30.f, 0.f), Vec3(0.f, 0.6f, -0.8f)).is_black());
    EXPECT_EQ(bsdf->pdf(si, Vec3(0.f, 0.6f, -0.8f), direction_deg(30.f, 0.f)), 0.f);
  }
}

TEST(Phong, EvalIsNormalisedLobePlusLambert) {
  SurfaceInteraction si;
  const float n = 12.f;
  auto bsdf = phong(Rgb(0.3f), Rgb(0.6f), n);
  Vec3 wo = direction_deg(30.f, 0.f);
  Vec3 wi = direction_deg(40.f, 180.f);  // 10 degrees from the mirror direction direction_deg(30, 180)
  float cos_a = std::cos(10.f * kPi / 180.f);
  float expect = (0.3f / kPi + 0.6f * (n + 2.f) / (2.f * kPi) * std::pow(cos_a, n)) * wi.z;
  EXPECT_NEAR(bsdf->eval(si, wo, wi).g, expect, 1e-5f);
  // pdf mixes both lobes with Mitsuba's specular sampling weight (luminance 0.6 / 0.9).
  float w = 0.6f / 0.9f;
  float pdf = w * (n + 1.f) / (2.f * kPi) * std::pow(cos_a, n) + (1.f - w) * wi.z / kPi;
  EXPECT_NEAR(bsdf->pdf(si, wo, wi), pdf, 1e-5f);
}

// The lobe is chosen with probability = the specular sampling weight: u1 below it gives samples
// around the mirror direction, above it the diffuse lobe (which is the only one when ks = 0).
TEST(Phong, LobeChoiceFollowsSpecularSamplingWeight) {
  auto d = constant(Rgb(0.6f, 0.2f, 0.2f)), s = constant(Rgb(0.1f, 0.3f, 0.1f));
  float w = phong_specular_sampling_weight(*d, *s);
  EXPECT_NEAR(w, s->mean().luminance() / (s->mean().luminance() + d->mean().luminance()), 1e-6f);
  auto bsdf = make_phong_bsdf(d, s, constant(Rgb(1000.f)), w);
  SurfaceInteraction si;
  Vec3 wo = direction_deg(30.f, 0.f), mirror = direction_deg(30.f, 180.f);
  BsdfSample bs;
  ASSERT_TRUE(bsdf->sample(si, wo, 0.999f * w, {0.9f, 0.9f}, bs));
  EXPECT_GT(dot(bs.wi, mirror), 0.99f);
  ASSERT_TRUE(bsdf->sample(si, wo, w + 0.001f, {0.9f, 0.9f}, bs));
  EXPECT_LT(dot(bs.wi, mirror), 0.9f);
  // Count the choices over many samples: the fraction near the mirror direction is w (the
  // diffuse lobe puts almost nothing within the narrow n = 1000 lobe).
  Pcg32 rng(21);
  int near = 0, total = 20000;
  for (int i = 0; i < total; ++i)
    if (bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs) && dot(bs.wi, mirror) > 0.99f)
      ++near;
  EXPECT_NEAR(double(near) / total, w, 0.015);
  EXPECT_EQ(phong_specular_sampling_weight(*d, *constant(Rgb(0.f))), 0.f);
}

// White furnace: diffuse + specular = 1 (and pure specular 1): albedo <= 1 at every angle, and the
// normalised lobe reflects exactly everything at normal incidence.
TEST(Phong, WhiteFurnaceAlbedoAtMostOne) {
  SurfaceInteraction si;
  for (float n : {1.f, 10.f, 100.f}) {
    for (float ks : {0.5f, 1.f}) {
      auto bsdf = phong(Rgb(1.f - ks), Rgb(ks), n);
      for (Vec3 wo : kWo) {
        Pcg32 rng(13);
        const int count = 40000;
        double sum = 0;
        for (int i = 0; i < count; ++i) {
          BsdfSample bs;
          if (bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) sum += bs.weight.g;
        }
        double albedo = sum / count;
        EXPECT_LE(albedo, 1.0 + 1e-2) << "n " << n << " ks " << ks << " wo.z " << wo.z;
        if (wo.z == 1.f && ks == 1.f) {
          EXPECT_NEAR(albedo, 1.0, 1e-2) << "n " << n;
        }
      }
    }
  }
}

LoadResult load_06(const std::string& body) {
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/phong.xml"), {});
}

TEST(Phong, LoadsFromMitsuba06Xml) {
  SurfaceInteraction si;
  Vec3 wo = direction_deg(30.f, 0.f), wi = direction_deg(35.f, 175.f);
  auto r = load_06(R"(<shape type="sphere"><bsdf type="phong">
    <rgb name="diffuseReflectance" value="0.7 0.439632 0.1"/>
    <rgb name="specularReflectance" value="0.1 0.1 0.1"/>
    <float name="exponent" value="40"/></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ASSERT_FALSE(r.scene->shapes.empty());
  const Bsdf* b = r.scene->shapes.at(0)->bsdf;
  ASSERT_NE(b, nullptr);
  auto ref = phong(Rgb(0.7f, 0.439632f, 0.1f), Rgb(0.1f), 40.f);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(b->eval(si, wo, wi)[c], ref->eval(si, wo, wi)[c], 1e-6f);
  EXPECT_NEAR(b->pdf(si, wo, wi), ref->pdf(si, wo, wi), 1e-6f);

  // Defaults: diffuse 0.5, specular 0.2, exponent 30.
  r = load_06(R"(<shape type="sphere"><bsdf type="phong"/></shape>)");
  ref = phong(Rgb(0.5f), Rgb(0.2f), 30.f);
  EXPECT_NEAR(r.scene->shapes.at(0)->bsdf->eval(si, wo, wi).g, ref->eval(si, wo, wi).g, 1e-6f);
  EXPECT_NEAR(r.scene->shapes.at(0)->bsdf->pdf(si, wo, wi), ref->pdf(si, wo, wi), 1e-6f);

  // Exponent as a texture.
  r = load_06(R"(<shape type="sphere"><bsdf type="phong">
    <texture type="checkerboard" name="exponent"><float name="color0" value="8"/><float name="color1" value="8"/></texture>
    </bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ref = phong(Rgb(0.5f), Rgb(0.2f), 8.f);
  EXPECT_NEAR(r.scene->shapes.at(0)->bsdf->eval(si, wo, wi).g, ref->eval(si, wo, wi).g, 1e-5f);

  // Not energy conserving (0.8 + 0.6): both scaled by 0.99 / 1.4, as Mitsuba does.
  r = load_06(R"(<shape type="sphere"><bsdf type="phong">
    <rgb name="diffuseReflectance" value="0.8"/><rgb name="specularReflectance" value="0.6"/></bsdf></shape>)");
  float s = 0.99f / 1.4f;
  ref = phong(Rgb(0.8f * s), Rgb(0.6f * s), 30.f);
  EXPECT_NEAR(r.scene->shapes.at(0)->bsdf->eval(si, wo, wi).g, ref->eval(si, wo, wi).g, 1e-5f);
  bool warned = false;
  for (const auto& m : r.messages) warned |= m.text.find("phong") != std::string::npos;
  EXPECT_TRUE(warned);
  r = load_06(R"(<shape type="sphere"><bsdf type="phong"><boolean name="ensureEnergyConservation" value="false"/>
    <rgb name="diffuseReflectance" value="0.8"/><rgb name="specularReflectance" value="0.6"/></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ref = phong(Rgb(0.8f), Rgb(0.6f), 30.f);
  EXPECT_NEAR(r.scene->shapes.at(0)->bsdf->eval(si, wo, wi).g, ref->eval(si, wo, wi).g, 1e-5f);
}

}  // namespace
}  // namespace tessera
