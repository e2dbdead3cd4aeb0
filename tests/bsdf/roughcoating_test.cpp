// roughcoating: chi-square of sample() against pdf() over distributions, roughness, IOR and
// incidence; weights against eval/pdf; the closed forms (a Lambertian under the coat with the rough
// transmittance, absorption along the refracted directions, the smooth coating as alpha -> 0);
// textured roughness; energy; a delta nested BSDF; grazing angles; loading from Mitsuba 0.6 XML.
#include "tessera/bsdf/coating.h"

#include "bsdf_test_util.h"
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/diffuse.h"
#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/rough_transmittance.h"
#include "tessera/core/hash.h"
#include "tessera/scene/load_context.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace tessera {
namespace {

using test::constant;
using test::kWo;

// A constant that is not a ConstantTexture, to take the textured-roughness path.
class UniformTexture final : public Texture {
 public:
  explicit UniformTexture(float v) : v_(v) {}
  Rgb eval(const SurfaceInteraction&) const override { return Rgb(v_); }
  Rgb mean() const override { return Rgb(v_); }

 private:
  float v_;
};

TEST(RoughCoating, Chi2SampleMatchesPdf) {
  struct Case {
    MicrofacetType type;
    float alpha, eta;
    std::shared_ptr<Bsdf> nested;
    Rgb sigma_a;
  };
  const std::vector<Case> cases = {
      {MicrofacetType::Beckmann, 0.05f, 1.5f, make_diffuse_bsdf(constant(0.5f)), Rgb(0.f)},
      {MicrofacetType::Beckmann, 0.3f, 1.33f, test::rough_metal("Cu", MicrofacetType::Beckmann, 0.2f), Rgb(0.f)},
      {MicrofacetType::Beckmann, 1.f, 1.7f, make_diffuse_bsdf(constant(0.8f)), Rgb(0.5f, 1.f, 2.f)},
      {MicrofacetType::Ggx, 0.1f, 2.f, make_diffuse_bsdf(constant(0.5f)), Rgb(0.f)},
      {MicrofacetType::Ggx, 1.f, 1.5f, test::rough_metal("Au", MicrofacetType::Ggx, 0.5f), Rgb(0.3f)},
      {MicrofacetType::Phong, 0.3f, 1.5f, make_diffuse_bsdf(constant(0.5f)), Rgb(0.f)},
  };
  const int test_count = int(cases.size() * std::size(kWo));
  for (const Case& c : cases) {
    auto bsdf = make_roughcoating_bsdf(c.type, constant(c.alpha), c.eta, 1.f, constant(c.sigma_a), constant(1.f),
                                       c.nested.get());
    for (Vec3 wo : kWo) {
      auto r = test::lobe_chi2_test(*bsdf, wo, c.alpha, test_count, "roughcoating");
      EXPECT_TRUE(r.passed) << "type " << int(c.type) << " alpha " << c.alpha << " eta " << c.eta << " wo.z "
                            << wo.z << "\n" << r.message;
    }
  }
}

TEST(RoughCoating, WeightIsEvalOverPdf) {
  auto nested = test::rough_metal("Cu", MicrofacetType::Ggx, 0.3f);
  auto bsdf = make_roughcoating_bsdf(MicrofacetType::Ggx, constant(0.2f), 1.5f, 1.f, constant(Rgb(0.1f, 0.2f, 0.3f)),
                                     constant(0.9f), nested.get());
  EXPECT_FALSE(bsdf->is_delta());
  int ok = 0;
  ASSERT_NO_FATAL_FAILURE(test::expect_weight_is_eval_over_pdf(*bsdf, ok));
  EXPECT_GT(ok, 2000);  // from grazing incidence many reflections end below the horizon
}

// A Lambertian under the coat: rho/pi cos_i T(cos_o) T(cos_i) / eta^2, T the rough transmittance;
// away from the mirror direction of a nearly smooth coat that is the smooth coating's value.
TEST(RoughCoating, LambertianUnderCoatClosedFormAndSmoothLimit) {
  const float eta = 1.5f, rho = 0.7f, alpha = 0.4f;
  auto nested = make_diffuse_bsdf(constant(rho));
  auto rough = make_roughcoating_bsdf(MicrofacetType::Beckmann, constant(alpha), eta, 1.f, constant(0.f),
                                      constant(0.f), nested.get());  // specular_reflectance 0: nested part only
  auto smoothish = make_roughcoating_bsdf(MicrofacetType::Beckmann, constant(1e-3f), eta, 1.f, constant(0.f),
                                          constant(1.f), nested.get());
  auto smooth = make_coating_bsdf(eta, 1.f, constant(0.f), constant(1.f), nested.get());
  SurfaceInteraction si;
  for (Vec3 wo : kWo) {
    for (float theta : {0.f, 30.f, 60.f, 85.f}) {
      const Vec3 wi = test::direction_deg(theta, 200.f);
      const float t_o = rough_dielectric_transmittance(MicrofacetType::Beckmann, alpha, eta, wo.z);
      const float t_i = rough_dielectric_transmittance(MicrofacetType::Beckmann, alpha, eta, wi.z);
      const float expected = rho * kInvPi * wi.z * t_o * t_i / (eta * eta);
      // The table interpolates T linearly in cos theta.
      EXPECT_NEAR(rough->eval(si, wo, wi).g, expected, 5e-3f * expected) << wo.z << " " << theta;
      if (dot(normalize(wo + wi), Vec3(0.f, 0.f, 1.f)) < 0.99f) {
        const float s = smooth->eval(si, wo, wi).g;
        EXPECT_NEAR(smoothish->eval(si, wo, wi).g, s, 5e-3f * s) << wo.z << " " << theta;
      }
    }
  }
  for (int i = 0; i < 3; ++i) {
    const test::AlbedoEstimate a = test::albedo(*smoothish, kWo[i]), b = test::albedo(*smooth, kWo[i]);
    EXPECT_NEAR(a.mean, b.mean, 4 * (a.se + b.se) + 5e-3) << kWo[i].z;
  }
}

TEST(RoughCoating, AbsorptionAlongRefractedDirections) {
  const float eta = 1.4f, d = 0.7f;
  const Rgb sigma(0.1f, 0.5f, 2.f);
  auto nested = test::rough_metal("Ag", MicrofacetType::Ggx, 0.5f);
  // No interface reflection, so that the ratio isolates the nested part.
  auto clear = make_roughcoating_bsdf(MicrofacetType::Ggx, constant(0.2f), eta, d, constant(0.f), constant(0.f),
                                      nested.get());
  auto tinted = make_roughcoating_bsdf(MicrofacetType::Ggx, constant(0.2f), eta, d, constant(sigma), constant(0.f),
                                       nested.get());
  test::expect_absorption_along_refracted(*clear, *tinted, nullptr, eta, d, sigma);
}

// A textured roughness uses tables over alpha: at a node it matches the constant-alpha tables,
// between nodes it interpolates closely.
TEST(RoughCoating, TexturedAlpha) {
  auto nested = make_diffuse_bsdf(constant(0.5f));
  SurfaceInteraction si;
  for (float alpha : {0.3f, 0.25f, 0.73f}) {
    auto fixed = make_roughcoating_bsdf(MicrofacetType::Ggx, constant(alpha), 1.5f, 1.f, constant(0.f),
                                        constant(1.f), nested.get());
    auto textured = make_roughcoating_bsdf(MicrofacetType::Ggx, std::make_shared<UniformTexture>(alpha), 1.5f, 1.f,
                                           constant(0.f), constant(1.f), nested.get());
    for (Vec3 wo : kWo) {
      for (float theta : {0.f, 45.f, 80.f}) {
        const Vec3 wi = test::direction_deg(theta, 10.f);
        const float a = fixed->eval(si, wo, wi).g, b = textured->eval(si, wo, wi).g;
        EXPECT_NEAR(b, a, 3e-3f * a) << alpha << " " << wo.z << " " << theta;
        EXPECT_NEAR(textured->pdf(si, wo, wi), fixed->pdf(si, wo, wi), 3e-3f * fixed->pdf(si, wo, wi));
      }
    }
  }
}

// White furnace: a white Lambertian or a lossless rough mirror under the coat reflects at most
// everything; a perfect (delta) mirror under it as well, through delta nested samples.
TEST(RoughCoating, WhiteFurnace) {
  auto white = make_diffuse_bsdf(constant(1.f));
  auto rough_mirror = test::rough_metal("none", MicrofacetType::Beckmann, 0.2f);
  auto mirror = make_conductor_bsdf(*lookup_metal("none"), constant(1.f));
  for (MicrofacetType type : {MicrofacetType::Beckmann, MicrofacetType::Ggx}) {
    for (float alpha : {0.05f, 0.3f, 1.f}) {
      for (const Bsdf* nested : {static_cast<const Bsdf*>(white.get()), static_cast<const Bsdf*>(rough_mirror.get()),
                                 static_cast<const Bsdf*>(mirror.get())}) {
        auto bsdf = make_roughcoating_bsdf(type, constant(alpha), 1.5f, 1.f, constant(0.f), constant(1.f), nested);
        for (Vec3 wo : kWo) {
          const test::AlbedoEstimate a = test::albedo(*bsdf, wo);
          EXPECT_LE(a.mean, 1.0 + 4 * a.se + 1e-3) << int(type) << " " << alpha << " " << wo.z;
          EXPECT_GT(a.mean, 0.1) << int(type) << " " << alpha << " " << wo.z;  // GGX alpha 1 at grazing: ~0.13
        }
      }
    }
  }
  // The delta mirror's samples stay delta, leave at the mirror direction, and carry the lobe choice.
  auto bsdf = make_roughcoating_bsdf(MicrofacetType::Ggx, constant(0.3f), 1.5f, 1.f, constant(0.f), constant(1.f),
                                     mirror.get());
  EXPECT_FALSE(bsdf->is_delta());
  SurfaceInteraction si;
  BsdfSample bs;
  ASSERT_TRUE(bsdf->sample(si, kWo[1], 0.999f, {0.5f, 0.5f}, bs));
  ASSERT_TRUE(bs.delta);
  EXPECT_NEAR(bs.wi.x, -kWo[1].x, 1e-6f);
  EXPECT_NEAR(bs.wi.z, kWo[1].z, 1e-6f);
  const float t = rough_dielectric_transmittance(MicrofacetType::Ggx, 0.3f, 1.5f, kWo[1].z);
  EXPECT_NEAR(bs.weight.g * bs.pdf, t * t, 5e-3f);
}

TEST(RoughCoating, FiniteAtGrazingAngles) {
  auto diffuse = make_diffuse_bsdf(constant(0.5f));
  auto metal = test::rough_metal("Cu", MicrofacetType::Ggx, 0.05f);
  Pcg32 rng(31);
  for (const Bsdf* nested : {static_cast<const Bsdf*>(diffuse.get()), static_cast<const Bsdf*>(metal.get())}) {
    for (MicrofacetType type : {MicrofacetType::Beckmann, MicrofacetType::Ggx, MicrofacetType::Phong}) {
      auto bsdf = make_roughcoating_bsdf(type, constant(0.05f), 1.5f, 2.f, constant(Rgb(0.f, 0.5f, 3.f)),
                                         constant(1.f), nested);
      test::expect_finite_at_grazing(*bsdf, rng);
    }
  }
}

LoadResult load_06(const std::string& body) { return test::load_mitsuba06(body, "mem/rc.xml"); }

TEST(RoughCoating, LoadsMitsuba06Xml) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="roughcoating">
    <string name="distribution" value="ggx"/><float name="alpha" value="0.3"/>
    <boolean name="sampleVisible" value="true"/>
    <string name="intIOR" value="bk7"/><float name="extIOR" value="1.0"/>
    <float name="thickness" value="0.5"/><rgb name="sigmaA" value="0.2, 0.4, 0.8"/>
    <spectrum name="specularReflectance" value="0.8"/>
    <bsdf type="diffuse"><float name="reflectance" value="0.5"/></bsdf></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ASSERT_FALSE(r.scene->shapes.empty());
  auto nested = make_diffuse_bsdf(constant(0.5f));
  auto expected = make_roughcoating_bsdf(MicrofacetType::Ggx, constant(0.3f), 1.5046f, 0.5f,
                                         constant(Rgb(0.2f, 0.4f, 0.8f)), constant(0.8f), nested.get());
  const Bsdf& loaded = *r.scene->shapes.at(0)->bsdf;
  SurfaceInteraction si;
  const Vec3 wo = kWo[1];
  for (Vec3 wi : {normalize(Vec3(-0.4f, 0.2f, 0.7f)), normalize(Vec3(-0.6f, 0.3f, 0.5f))}) {
    const Rgb a = loaded.eval(si, wo, wi), b = expected->eval(si, wo, wi);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-6f * b[c]);
    EXPECT_NEAR(loaded.pdf(si, wo, wi), expected->pdf(si, wo, wi), 1e-6f * expected->pdf(si, wo, wi));
  }

  // Textured alpha and sigmaA, default distribution (beckmann).
  r = load_06(R"(<shape type="sphere"><bsdf type="roughcoating">
    <texture type="checkerboard" name="alpha"/><texture type="checkerboard" name="sigmaA"/>
    <bsdf type="roughconductor"/></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());

  // Mitsuba's errors: anisotropic roughness, equal IORs, no nested BSDF, unknown distribution.
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughcoating"><float name="alphaU" value="0.1"/>
    <float name="alphaV" value="0.3"/><bsdf type="diffuse"/></bsdf></shape>)"),
               SceneError);
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughcoating"><float name="intIOR" value="1.3"/>
    <float name="extIOR" value="1.3"/><bsdf type="diffuse"/></bsdf></shape>)"),
               SceneError);
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughcoating"/></shape>)"), SceneError);
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughcoating"><string name="distribution" value="blinn"/>
    <bsdf type="diffuse"/></bsdf></shape>)"),
               SceneError);
}

}  // namespace
}  // namespace tessera
