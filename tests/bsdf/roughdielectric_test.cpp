// roughdielectric: chi-square of sample() against pdf() over the whole sphere (reflection and
// refraction together) for every distribution, alpha 0.1..1, from outside (eta 1.5) and from inside
// (eta 1/1.5), incident angles normal..80 degrees; sample weight == eval / pdf; white furnace
// (R + T before the eta^2 radiance scaling) <= 1 and close to 1 for smooth surfaces; reciprocity;
// the 0.6 XML names.
#include "tessera/bsdf/roughdielectric.h"
#include "tessera/core/hash.h"
#include "tessera/core/ray.h"
#include "tessera/scene/load_context.h"
#include "support/chi2.h"

#include "bsdf/bsdf_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

namespace tessera {
namespace {

std::shared_ptr<Texture> constant(float v) { return std::make_shared<ConstantTexture>(Rgb(v)); }

const MicrofacetType kTypes[] = {MicrofacetType::Beckmann, MicrofacetType::Ggx, MicrofacetType::Phong};
const float kEta = 1.5f;

const char* type_name(MicrofacetType t) {
  return t == MicrofacetType::Beckmann ? "beckmann" : (t == MicrofacetType::Ggx ? "ggx" : "phong");
}

std::shared_ptr<Bsdf> make(MicrofacetType t, float alpha_u, float alpha_v = -1.f, float refl = 1.f,
                           float trans = 1.f) {
  return make_roughdielectric_bsdf(t, constant(alpha_u), alpha_v < 0.f ? nullptr : constant(alpha_v), kEta,
                                   constant(refl), constant(trans));
}

// `inside`: wo below the surface, i.e. light crossing from the eta = 1.5 medium (relative 1/1.5).
Vec3 direction(float deg, bool inside, float phi = 0.7f) {
  float th = deg * kPi / 180.f;
  Vec3 w(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
  return inside ? Vec3(w.x, w.y, -w.z) : w;
}

const float kAngles[] = {0.f, 45.f, 80.f};
const float kAlphas[] = {0.1f, 0.4f, 1.f};

TEST(RoughDielectric, Chi2SamplingMatchesPdf) {
  const int tests = int(std::size(kTypes) * std::size(kAlphas) * std::size(kAngles) * 2);
  SurfaceInteraction si;
  for (MicrofacetType t : kTypes) {
    for (float alpha : kAlphas) {
      auto b = make(t, alpha);
      for (bool inside : {false, true}) {
        for (float deg : kAngles) {
          Vec3 wo = direction(deg, inside);
          test::Chi2Options o;
          o.test_count = tests;
          o.sample_count = 200000;
          o.name = std::string(type_name(t)) + " alpha " + std::to_string(alpha) + (inside ? " inside" : " outside") +
                   " theta_o " + std::to_string(deg);
          if (t == MicrofacetType::Ggx && alpha > 0.2f && deg >= 80.f) {
            // GGX keeps a non-zero density at the horizon, so the refracted directions reachable
            // from a grazing wo end on a sharp edge (cos theta_i ~ -0.11 at alpha 1): a step in the
            // pdf that coarse Simpson bins integrate badly. Fine bins there.
            o.cos_theta_bins = 400;
            o.phi_bins = 200;
            o.sample_count = 600000;
          }
          if (alpha < 0.2f) {
            // Narrow reflected and refracted lobes: finer bins. Leaving the dense side, the refracted
            // lobe is about half as wide as the micro-normal lobe (a cap of ~0.002 in cos theta).
            o.cos_theta_bins = 400;
            o.phi_bins = 120;
            o.sample_count = 600000;
            o.integration_resolution = 6;
            if (deg == 0.f) {
              // The refracted lobe then sits in the polar bin, ~0.0005 wide in cos theta entering:
              // Simpson needs more nodes there (the pdf itself integrates to 1 on a fine polar grid).
              // The lobes are rotationally symmetric, so few phi bins suffice.
              o.phi_bins = 24;
              o.integration_resolution = 16;
            }
          }
          auto r = test::bsdf_chi2_test(*b, si, wo, o);
          EXPECT_TRUE(r.passed) << r.message;
          EXPECT_LE(r.pdf_integral, 1.0 + 1e-2) << o.name;
        }
      }
    }
  }
}

TEST(RoughDielectric, SampleWeightIsEvalOverPdf) {
  SurfaceInteraction si;
  int reflected = 0, refracted = 0;
  for (MicrofacetType t : kTypes) {
    for (float alpha : {0.05f, 0.3f, 1.f}) {
      // Anisotropic as well, and coloured textures to tell the lobes apart.
      for (float alpha_v : {-1.f, 0.6f}) {
        auto b = make(t, alpha, alpha_v, 0.8f, 0.6f);
        Pcg32 rng(11);
        for (bool inside : {false, true}) {
          for (float deg : {0.f, 30.f, 60.f, 85.f}) {
            Vec3 wo = direction(deg, inside);
            for (int i = 0; i < 200; ++i) {
              BsdfSample bs;
              if (!b->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
              EXPECT_FALSE(bs.delta);
              const bool refract = bs.wi.z * wo.z < 0.f;
              (refract ? refracted : reflected)++;
              EXPECT_FLOAT_EQ(bs.eta, refract ? (inside ? 1.f / kEta : kEta) : 1.f);
              float pdf = b->pdf(si, wo, bs.wi);
              ASSERT_GT(pdf, 0.f);
              EXPECT_NEAR(bs.pdf, pdf, 2e-3f * pdf + 1e-5f);
              Rgb ratio = b->eval(si, wo, bs.wi) / pdf;
              for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(bs.weight[c], ratio[c], 3e-3f * ratio[c] + 1e-5f)
                    << type_name(t) << " " << alpha << " " << deg << (inside ? " inside" : "");
            }
          }
        }
      }
    }
  }
  EXPECT_GT(reflected, 1000);
  EXPECT_GT(refracted, 1000);
}

// Any direction, grazing ones included: finite, non-negative values and weights.
TEST(RoughDielectric, FiniteEverywhere) {
  SurfaceInteraction si;
  Pcg32 rng(23);
  for (MicrofacetType t : kTypes) {
    for (float alpha : {0.01f, 0.2f, 1.f}) {
      auto b = make(t, alpha);
      for (int i = 0; i < 2000; ++i) {
        float z = 2.f * rng.next_float() - 1.f, phi = 2.f * kPi * rng.next_float();
        float r = std::sqrt(std::max(0.f, 1.f - z * z));
        Vec3 wo(r * std::cos(phi), r * std::sin(phi), z);
        BsdfSample bs;
        if (b->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) {
          EXPECT_TRUE(std::isfinite(bs.weight.g) && bs.weight.g >= 0.f) << type_name(t) << " " << z;
          EXPECT_TRUE(std::isfinite(bs.pdf) && bs.pdf > 0.f);
        }
        Vec3 wi(-wo.y, wo.x, -wo.z);
        float f = b->eval(si, wo, wi).g, p = b->pdf(si, wo, wi);
        EXPECT_TRUE(std::isfinite(f) && f >= 0.f && std::isfinite(p) && p >= 0.f);
      }
    }
  }
}

// Generalised reciprocity: eval / |cos_i| is f; reflection is symmetric, and the radiance-scaled
// refraction satisfies f(wo, wi) / n_o^2 == f(wi, wo) / n_i^2.
TEST(RoughDielectric, Reciprocity) {
  SurfaceInteraction si;
  Pcg32 rng(5);
  for (MicrofacetType t : kTypes) {
    auto b = make(t, 0.4f);
    for (int i = 0; i < 200; ++i) {
      Vec3 a = direction(85.f * rng.next_float(), false, 2.f * kPi * rng.next_float());
      Vec3 c = direction(85.f * rng.next_float(), rng.next_float() < 0.5f, 2.f * kPi * rng.next_float());
      float f_ac = b->eval(si, a, c).g / std::abs(c.z);
      float f_ca = b->eval(si, c, a).g / std::abs(a.z);
      if (c.z > 0.f) {
        EXPECT_NEAR(f_ac, f_ca, 1e-4f * f_ac + 1e-6f);
      } else {
        EXPECT_NEAR(f_ac * kEta * kEta, f_ca, 1e-3f * f_ca + 1e-6f) << type_name(t);
      }
    }
  }
}

// Directional albedo R + T, the refracted weights taken before the radiance scaling (weight *
// bs.eta^2 undoes it). Single scattering loses energy to masking as roughness grows (printed as a
// table); never above 1 beyond noise; nearly 1 for smooth surfaces away from grazing.
TEST(RoughDielectric, WhiteFurnaceAlbedo) {
  SurfaceInteraction si;
  const float alphas[] = {0.05f, 0.1f, 0.3f, 0.6f, 1.f};
  const float angles[] = {0.f, 45.f, 80.f};
  const int n = 60000;
  for (MicrofacetType t : kTypes) {
    for (bool inside : {false, true}) {
      std::printf("[furnace] %-8s %-7s theta_o:", type_name(t), inside ? "inside" : "outside");
      for (float deg : angles) std::printf("  %6.0f", deg);
      std::printf("\n");
      for (float alpha : alphas) {
        auto b = make(t, alpha);
        std::printf("[furnace]   alpha %.2f:       ", alpha);
        for (float deg : angles) {
          Vec3 wo = direction(deg, inside);
          Pcg32 rng(7);
          double sum = 0, sum2 = 0;
          for (int i = 0; i < n; ++i) {
            BsdfSample bs;
            double w = 0;
            if (b->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs))
              w = double(bs.weight.g) * double(bs.eta) * double(bs.eta);
            sum += w;
            sum2 += w * w;
          }
          double mean = sum / n, stderr_ = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
          std::printf("  %6.4f", mean);
          double tol = t == MicrofacetType::Ggx ? 2e-3 : 6e-3;  // Beckmann's rational G1 (see roughconductor)
          if (t == MicrofacetType::Phong && alpha >= 0.5f) tol = 0.2;  // Mitsuba's Phong G1 overshoots
          EXPECT_LE(mean, 1.0 + tol + 4.0 * stderr_) << type_name(t) << " alpha " << alpha << " theta " << deg;
          if (alpha <= 0.1f && deg <= 45.f) {
            // From inside at 45 degrees (beyond the critical angle) GGX's long tails lose ~3%.
            EXPECT_GT(mean, 0.96) << type_name(t) << " alpha " << alpha << " theta " << deg;
          }
        }
        std::printf("\n");
      }
    }
  }
}

// Roughness given as a texture is looked up at the shading point.
class SplitTexture final : public Texture {
 public:
  Rgb eval(const SurfaceInteraction& si) const override { return Rgb(si.uv.x < 0.5f ? 0.1f : 0.6f); }
  Rgb mean() const override { return Rgb(0.35f); }
};

TEST(RoughDielectric, TexturedAlphaIsEvaluatedAtTheHit) {
  auto textured = make_roughdielectric_bsdf(MicrofacetType::Ggx, std::make_shared<SplitTexture>(), nullptr, kEta,
                                            constant(1.f), constant(1.f));
  auto smooth = make(MicrofacetType::Ggx, 0.1f), rough = make(MicrofacetType::Ggx, 0.6f);
  SurfaceInteraction left, right;
  left.uv = Vec2(0.2f, 0.5f);
  right.uv = Vec2(0.8f, 0.5f);
  Vec3 wo = direction(30.f, false), wi = direction(25.f, true, 0.7f + kPi);
  EXPECT_EQ(textured->eval(left, wo, wi), smooth->eval(left, wo, wi));
  EXPECT_EQ(textured->eval(right, wo, wi), rough->eval(right, wo, wi));
  EXPECT_EQ(textured->pdf(right, wo, wi), rough->pdf(right, wo, wi));
  EXPECT_NE(textured->eval(left, wo, wi), textured->eval(right, wo, wi));
}

LoadResult load_06(const std::string& body) {
  LoadOptions opts;
  opts.allow_unsupported = true;
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/rough.xml"),
                    opts);
}

TEST(RoughDielectric, FactoryReadsMitsuba06Names) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="roughdielectric">
    <string name="distribution" value="ggx"/>
    <float name="alphaU" value="0.2"/><float name="alphaV" value="0.5"/>
    <float name="intIOR" value="1.5"/><string name="extIOR" value="vacuum"/>
    <rgb name="specularReflectance" value="0.5"/><spectrum name="specularTransmittance" value="0.25"/>
  </bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ASSERT_FALSE(r.scene->shapes.empty());
  const Bsdf& loaded = *r.scene->shapes.at(0)->bsdf;
  auto expected = make(MicrofacetType::Ggx, 0.2f, 0.5f, 0.5f, 0.25f);
  SurfaceInteraction si;
  Vec3 wo = direction(40.f, false);
  for (Vec3 wi : {direction(30.f, false, 3.5f), direction(20.f, true, 3.8f)}) {
    EXPECT_NEAR(loaded.eval(si, wo, wi).g, expected->eval(si, wo, wi).g, 1e-6f);
    EXPECT_NEAR(loaded.pdf(si, wo, wi), expected->pdf(si, wo, wi), 1e-6f);
  }
  // Defaults: beckmann, alpha 0.1, bk7 in air; an unknown distribution is an error.
  r = load_06(R"(<shape type="sphere"><bsdf type="roughdielectric"/></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  auto def = make_roughdielectric_bsdf(MicrofacetType::Beckmann, constant(0.1f), nullptr, 1.5046f / 1.000277f,
                                       constant(1.f), constant(1.f));
  Vec3 wi = direction(15.f, true, 3.9f);
  EXPECT_NEAR(r.scene->shapes.at(0)->bsdf->eval(si, wo, wi).g, def->eval(si, wo, wi).g,
              1e-5f * def->eval(si, wo, wi).g);
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughdielectric">
    <string name="distribution" value="blinn"/></bsdf></shape>)"),
               SceneError);
}

}  // namespace
}  // namespace tessera
