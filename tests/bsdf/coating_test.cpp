// coating: chi-square of the nested lobe seen through the interface against pdf(); Mitsuba's choice
// between the delta reflection and the nested BSDF; weights against eval/pdf; the closed forms
// (a Lambertian under the coat, absorption along the refracted directions, an invisible interface
// with int_ior == ext_ior, a perfect mirror under the coat: R + (1 - R)^2); energy; both sides;
// grazing angles; loading from Mitsuba 0.6 XML.
#include "tessera/bsdf/coating.h"

#include "bsdf_test_util.h"
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/dielectric.h"
#include "tessera/bsdf/diffuse.h"
#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/roughplastic.h"
#include "tessera/core/hash.h"
#include "tessera/scene/load_context.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace tessera {
namespace {

using test::constant;
using test::kWo;

// Mitsuba's probability of the delta reflection.
float expected_p_spec(float cos_o, float eta, Rgb sigma_a, float thickness) {
  const float avg = (std::exp(-2 * thickness * sigma_a.r) + std::exp(-2 * thickness * sigma_a.g) +
                     std::exp(-2 * thickness * sigma_a.b)) / 3;
  const float w = 1 / (avg + 1), f = fresnel_dielectric(cos_o, eta);
  return f * w / (f * w + (1 - f) * (1 - w));
}

TEST(Coating, Chi2NestedLobeMatchesPdf) {
  struct Case {
    std::shared_ptr<Bsdf> nested;
    float eta, alpha;
    Rgb sigma_a;
  };
  std::vector<Case> cases = {{make_diffuse_bsdf(constant(0.5f)), 1.5f, 1.f, Rgb(0.f)}};
  for (float alpha : {0.05f, 0.3f, 1.f}) {
    cases.push_back({test::rough_metal("Cu", MicrofacetType::Beckmann, alpha), 1.33f, alpha, Rgb(0.f)});
    cases.push_back({test::rough_metal("Au", MicrofacetType::Ggx, alpha), 2.f, alpha, Rgb(0.2f, 0.5f, 1.f)});
  }
  cases.push_back({make_roughplastic_bsdf(MicrofacetType::Phong, 0.2f, 1.49f, constant(0.5f), constant(1.f), false),
                   1.7f, 0.2f, Rgb(0.3f)});
  test::Chi2Options o;
  o.test_count = int(cases.size() * std::size(kWo));
  o.name = "coating";
  o.sample_count = 200000;
  for (const Case& c : cases) {
    auto bsdf = make_coating_bsdf(c.eta, 1.f, constant(c.sigma_a), constant(1.f), c.nested.get());
    for (Vec3 wo : kWo) {
      test::Chi2Options oc = o;
      if (c.alpha < 0.1f) {
        // Narrow nested lobes: finer bins.
        oc.cos_theta_bins = 200;
        oc.phi_bins = 400;
        oc.sample_count = 600000;
      } else if (wo.z < 0.2f || c.eta > 1.8f) {
        // Few nested samples leave the layer (most exceed the critical angle inside): more samples.
        oc.sample_count = 600000;
      }
      // The nested lobe alone: u1 is confined to the nested choice, and the density is pdf()
      // conditioned on that choice (at grazing incidence the delta reflection takes most samples).
      const float p_nested = 1.f - expected_p_spec(std::abs(wo.z), c.eta, c.sigma_a, 1.f);
      auto r = test::chi2_test(
          test::Chi2Sampler3([&](Vec2 u, float u1) -> test::Chi2Sample {
            SurfaceInteraction si;
            BsdfSample bs;
            const float u1n = std::min(1.f - p_nested + u1 * p_nested, 0x1.fffffep-1f);
            if (!bsdf->sample(si, wo, u1n, u, bs)) return {Vec3(), 0.f, false};
            EXPECT_FALSE(bs.delta);
            return {bs.wi, bs.pdf / p_nested, true};
          }),
          [&](Vec3 wi) {
            SurfaceInteraction si;
            return double(bsdf->pdf(si, wo, wi)) / p_nested;
          },
          oc);
      EXPECT_TRUE(r.passed) << "eta " << c.eta << " alpha " << c.alpha << " wo.z " << wo.z << "\n" << r.message;
    }
  }
}

TEST(Coating, SpecularChoiceAndWeights) {
  auto nested = make_diffuse_bsdf(constant(Rgb(0.6f, 0.3f, 0.2f)));
  SurfaceInteraction si;
  for (Rgb sigma_a : {Rgb(0.f), Rgb(0.5f, 1.f, 2.f)}) {
    const float thickness = 0.8f, eta = 1.6f;
    auto bsdf = make_coating_bsdf(eta, thickness, constant(sigma_a), constant(0.9f), nested.get());
    EXPECT_FALSE(bsdf->is_delta());
    for (Vec3 wo : kWo) {
      const float f = fresnel_dielectric(wo.z, eta), p_spec = expected_p_spec(wo.z, eta, sigma_a, thickness);
      Pcg32 rng(11);
      const int n = 20000;
      int n_spec = 0;
      for (int i = 0; i < n; ++i) {
        BsdfSample bs;
        if (!bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
        if (bs.delta) {
          ++n_spec;
          EXPECT_EQ(bs.wi, Vec3(-wo.x, -wo.y, wo.z));
          EXPECT_NEAR(bs.pdf, p_spec, 1e-5f);
          EXPECT_NEAR(bs.weight.g, 0.9f * f / p_spec, 1e-4f * f / p_spec);
        } else {
          const float pdf = bsdf->pdf(si, wo, bs.wi);
          const Rgb ratio = bsdf->eval(si, wo, bs.wi) / pdf;
          EXPECT_NEAR(bs.pdf, pdf, 1e-4f * pdf);
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], ratio[c], 1e-4f * ratio[c] + 1e-8f);
        }
      }
      const double sigma = std::sqrt(p_spec * (1 - p_spec) / n);
      EXPECT_NEAR(double(n_spec) / n, p_spec, 4 * sigma + 1e-9) << "wo.z " << wo.z;
    }
  }
}

// A Lambertian under the coat: rho/pi cos_i (1 - F(cos_o)) (1 - F(cos_i)) / eta^2 (the refracted
// cosine of the nested eval cancels against the solid-angle compression).
TEST(Coating, LambertianUnderCoatClosedForm) {
  const float eta = 1.5f, rho = 0.7f;
  auto nested = make_diffuse_bsdf(constant(rho));
  auto bsdf = make_coating_bsdf(eta, 1.f, constant(0.f), constant(1.f), nested.get());
  SurfaceInteraction si;
  for (Vec3 wo : kWo) {
    for (float theta : {0.f, 30.f, 60.f, 85.f, 89.9f}) {
      const Vec3 wi = test::direction_deg(theta, 200.f);
      const float expected = rho * kInvPi * wi.z * (1 - fresnel_dielectric(wo.z, eta)) *
                             (1 - fresnel_dielectric(wi.z, eta)) / (eta * eta);
      EXPECT_NEAR(bsdf->eval(si, wo, wi).g, expected, 1e-5f * expected + 1e-9f) << wo.z << " " << theta;
      const float pdf_expected = (1 - expected_p_spec(wo.z, eta, Rgb(0.f), 1.f)) * kInvPi * wi.z / (eta * eta);
      EXPECT_NEAR(bsdf->pdf(si, wo, wi), pdf_expected, 1e-5f * pdf_expected + 1e-9f);
    }
  }
}

// Absorption scales the nested part by exp(-sigma_a d (1/cos_o' + 1/cos_i')), per channel.
TEST(Coating, AbsorptionAlongRefractedDirections) {
  const float eta = 1.4f, d = 0.7f;
  const Rgb sigma(0.1f, 0.5f, 2.f);
  auto nested = test::rough_metal("Ag", MicrofacetType::Ggx, 0.5f);
  auto clear = make_coating_bsdf(eta, d, constant(0.f), constant(1.f), nested.get());
  auto tinted = make_coating_bsdf(eta, d, constant(sigma), constant(1.f), nested.get());
  auto zero_thickness = make_coating_bsdf(eta, 0.f, constant(sigma), constant(1.f), nested.get());
  test::expect_absorption_along_refracted(*clear, *tinted, zero_thickness.get(), eta, d, sigma);
}

// int_ior == ext_ior and no absorption: the interface disappears, leaving the nested BSDF exactly.
TEST(Coating, InvisibleInterfaceIsTheNestedBsdf) {
  auto nested = make_roughplastic_bsdf(MicrofacetType::Ggx, 0.3f, 1.5f, constant(Rgb(0.5f, 0.2f, 0.1f)),
                                       constant(1.f), false);
  auto bsdf = make_coating_bsdf(1.f, 1.f, constant(0.f), constant(1.f), nested.get());
  SurfaceInteraction si;
  Pcg32 rng(5);
  for (int i = 0; i < 2000; ++i) {
    const Vec3 wo = kWo[i % 4];
    const float u1 = rng.next_float();
    const Vec2 u2(rng.next_float(), rng.next_float());
    BsdfSample s1, s2;
    const bool ok1 = bsdf->sample(si, wo, u1, u2, s1), ok2 = nested->sample(si, wo, u1, u2, s2);
    ASSERT_EQ(ok1, ok2);
    if (!ok1) continue;
    EXPECT_FALSE(s1.delta);
    EXPECT_EQ(s1.wi, s2.wi);
    EXPECT_NEAR(s1.pdf, s2.pdf, 1e-6f * s2.pdf);
    EXPECT_NEAR(s1.weight.r, s2.weight.r, 1e-6f * s2.weight.r);
    const Rgb a = bsdf->eval(si, wo, s2.wi), b = nested->eval(si, wo, s2.wi);
    EXPECT_NEAR(a.r, b.r, 1e-6f * b.r);
    EXPECT_NEAR(bsdf->pdf(si, wo, s2.wi), nested->pdf(si, wo, s2.wi), 1e-6f * s2.pdf);
  }
}

// What the coat's underside reflects back in is dropped (as in Mitsuba), so with R = F(cos_o):
//  - a perfect mirror under the coat: albedo R + (1 - R)^2 (it leaves at its entry angle);
//  - a white Lambertian: R + (1 - R)(1 - Fdr_int), Fdr_int the hemispherical average reflectance
//    of the interface seen from inside (total internal reflection included);
//  - a lossless rough mirror: at most 1.
TEST(Coating, EnergyWithLosslessAndWhiteNested) {
  auto mirror = make_conductor_bsdf(*lookup_metal("none"), constant(1.f));
  auto rough_mirror = test::rough_metal("none", MicrofacetType::Beckmann, 0.3f);
  auto white = make_diffuse_bsdf(constant(1.f));
  for (float eta : {1.33f, 1.5f, 2.2f}) {
    auto on_mirror = make_coating_bsdf(eta, 1.f, constant(0.f), constant(1.f), mirror.get());
    auto on_rough = make_coating_bsdf(eta, 1.f, constant(0.f), constant(1.f), rough_mirror.get());
    auto on_white = make_coating_bsdf(eta, 1.f, constant(0.f), constant(1.f), white.get());
    EXPECT_TRUE(on_mirror->is_delta());
    EXPECT_FALSE(on_rough->is_delta());
    for (Vec3 wo : kWo) {
      const float r = fresnel_dielectric(wo.z, eta);
      const test::AlbedoEstimate e = test::albedo(*on_mirror, wo);
      EXPECT_NEAR(e.mean, r + (1 - r) * (1 - r), 4 * e.se + 1e-4) << eta << " " << wo.z;
      const test::AlbedoEstimate w = test::albedo(*on_white, wo);
      EXPECT_NEAR(w.mean, r + (1 - r) * (1 - fresnel_diffuse_reflectance(1.f / eta)), 4 * w.se + 1e-3)
          << eta << " " << wo.z;
      const test::AlbedoEstimate a = test::albedo(*on_rough, wo);
      EXPECT_LE(a.mean, 1.0 + 4 * a.se + 1e-4) << eta << " " << wo.z;
      EXPECT_GT(a.mean, 0.3) << eta << " " << wo.z;  // ~0.43 at eta 2.2: much leaves beyond the critical angle
    }
  }
  // Through the coat the mirror still reflects specularly: the nested sample leaves at -wo's mirror.
  auto coat = make_coating_bsdf(1.5f, 1.f, constant(0.f), constant(1.f), mirror.get());
  SurfaceInteraction si;
  BsdfSample bs;
  ASSERT_TRUE(coat->sample(si, kWo[1], 0.999f, {0.5f, 0.5f}, bs));
  EXPECT_TRUE(bs.delta);
  EXPECT_NEAR(bs.wi.x, -kWo[1].x, 1e-6f);
  EXPECT_NEAR(bs.wi.y, -kWo[1].y, 1e-6f);
  EXPECT_NEAR(bs.wi.z, kWo[1].z, 1e-6f);
}

// Mitsuba's coating reflects on both sides; a one-sided nested BSDF contributes nothing from below.
TEST(Coating, BackSide) {
  auto nested = make_diffuse_bsdf(constant(0.5f));
  auto bsdf = make_coating_bsdf(1.5f, 1.f, constant(0.f), constant(1.f), nested.get());
  SurfaceInteraction si;
  const Vec3 wo = normalize(Vec3(0.3f, 0.1f, -0.8f));
  EXPECT_TRUE(bsdf->eval(si, wo, normalize(Vec3(-0.3f, 0.f, -0.9f))).is_black());
  const float f = fresnel_dielectric(-wo.z, 1.5f);
  BsdfSample bs;
  ASSERT_TRUE(bsdf->sample(si, wo, 0.f, {0.5f, 0.5f}, bs));
  EXPECT_TRUE(bs.delta);
  EXPECT_EQ(bs.wi, Vec3(-wo.x, -wo.y, wo.z));
  EXPECT_NEAR(bs.weight.g * bs.pdf, f, 1e-6f);
  EXPECT_FALSE(bsdf->sample(si, wo, 0.999f, {0.5f, 0.5f}, bs));
}

TEST(Coating, FiniteAtGrazingAngles) {
  auto diffuse = make_diffuse_bsdf(constant(0.5f));
  auto metal = test::rough_metal("Cu", MicrofacetType::Ggx, 0.05f);
  Pcg32 rng(31);
  for (const Bsdf* nested : {static_cast<const Bsdf*>(diffuse.get()), static_cast<const Bsdf*>(metal.get())}) {
    for (float eta : {1.5f, 1.f / 1.5f}) {
      auto bsdf = make_coating_bsdf(eta, 2.f, constant(Rgb(0.f, 0.5f, 3.f)), constant(1.f), nested);
      test::expect_finite_at_grazing(*bsdf, rng);
    }
  }
}

LoadResult load_06(const std::string& body) { return test::load_mitsuba06(body, "mem/coat.xml"); }

TEST(Coating, LoadsMitsuba06Xml) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="coating">
    <string name="intIOR" value="bk7"/><float name="extIOR" value="1.0"/>
    <float name="thickness" value="0.5"/><rgb name="sigmaA" value="0.2, 0.4, 0.8"/>
    <spectrum name="specularReflectance" value="0.8"/>
    <bsdf type="diffuse"><float name="reflectance" value="0.5"/></bsdf></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ASSERT_FALSE(r.scene->shapes.empty());
  const Bsdf& loaded = *r.scene->shapes.at(0)->bsdf;
  const float eta = 1.5046f;
  const Vec3 wo = kWo[1], wi = normalize(Vec3(-0.4f, 0.2f, 0.7f));
  const float len = 0.5f * (1 / test::cos_inside(wo.z, eta) + 1 / test::cos_inside(wi.z, eta));
  const float clear = 0.5f * kInvPi * wi.z * (1 - fresnel_dielectric(wo.z, eta)) * (1 - fresnel_dielectric(wi.z, eta)) /
                      (eta * eta);
  SurfaceInteraction si;
  EXPECT_NEAR(loaded.eval(si, wo, wi).b, clear * std::exp(-0.8f * len), 1e-6f);
  BsdfSample bs;
  ASSERT_TRUE(loaded.sample(si, wo, 0.f, {0.5f, 0.5f}, bs));
  ASSERT_TRUE(bs.delta);
  EXPECT_NEAR(bs.weight.g * bs.pdf, 0.8f * fresnel_dielectric(wo.z, eta), 1e-6f);

  // Textured sigmaA, a nested rough conductor, energy conservation of specularReflectance.
  r = load_06(R"(<shape type="sphere"><bsdf type="coating">
    <texture type="checkerboard" name="sigmaA"/><rgb name="specularReflectance" value="2"/>
    <bsdf type="roughconductor"><string name="material" value="Cu"/></bsdf></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ASSERT_TRUE(r.scene->shapes.at(0)->bsdf->sample(si, wo, 0.f, {0.5f, 0.5f}, bs));
  ASSERT_TRUE(bs.delta);
  EXPECT_NEAR(bs.weight.g * bs.pdf, 0.99f * fresnel_dielectric(wo.z, 1.5046f / 1.000277f), 1e-6f);

  // Mitsuba's errors: no nested BSDF, two, equal IORs.
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="coating"/></shape>)"), SceneError);
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="coating"><bsdf type="diffuse"/><bsdf type="diffuse"/>
    </bsdf></shape>)"),
               SceneError);
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="coating"><float name="intIOR" value="1.2"/>
    <float name="extIOR" value="1.2"/><bsdf type="diffuse"/></bsdf></shape>)"),
               SceneError);
}

}  // namespace
}  // namespace tessera
