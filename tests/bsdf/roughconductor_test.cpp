// roughconductor: chi-square of sample() against pdf() for every distribution, roughness 0.05..1
// (anisotropic too) and incident angles normal..grazing; sample weight == eval / pdf; white
// furnace (material "none", F = 1): albedo <= 1, close to 1 at low roughness.
#include "tessera/bsdf/conductor.h"
#include "tessera/core/hash.h"
#include "tessera/core/ray.h"
#include "support/chi2.h"

#include "bsdf/bsdf_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace tessera {
namespace {

std::shared_ptr<Texture> constant(float v) { return std::make_shared<ConstantTexture>(Rgb(v)); }

struct Alphas {
  float u, v;
};

const MicrofacetType kTypes[] = {MicrofacetType::Beckmann, MicrofacetType::Ggx, MicrofacetType::Phong};
const Alphas kAlphas[] = {{0.05f, 0.05f}, {0.2f, 0.2f}, {0.5f, 0.5f}, {1.f, 1.f}, {0.05f, 0.3f}, {0.6f, 0.15f}};

const char* type_name(MicrofacetType t) {
  return t == MicrofacetType::Beckmann ? "beckmann" : (t == MicrofacetType::Ggx ? "ggx" : "phong");
}

std::shared_ptr<Bsdf> make(MicrofacetType t, Alphas a, const char* metal = "Au") {
  return make_roughconductor_bsdf(t, constant(a.u), a.u == a.v ? nullptr : constant(a.v), *lookup_metal(metal),
                                  constant(1.f));
}

Vec3 direction(float deg, float phi = 0.7f) {
  float th = deg * kPi / 180.f;
  return Vec3(std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th));
}

const float kAngles[] = {0.f, 45.f, 75.f, 85.f};

TEST(RoughConductor, Chi2SamplingMatchesPdf) {
  const int tests = int(std::size(kTypes) * std::size(kAlphas) * std::size(kAngles));
  SurfaceInteraction si;
  for (MicrofacetType t : kTypes) {
    for (Alphas a : kAlphas) {
      auto b = make(t, a);
      for (float deg : kAngles) {
        Vec3 wo = direction(deg);
        test::Chi2Options o;
        o.test_count = tests;
        o.sample_count = 300000;
        o.name = std::string(type_name(t)) + " alpha " + std::to_string(a.u) + "/" + std::to_string(a.v) +
                 " theta_o " + std::to_string(deg);
        if (std::min(a.u, a.v) < 0.1f || deg >= 75.f) {
          // Narrow lobes; towards grazing the reflected lobe is squeezed against the horizon into
          // a thin ridge in phi (width ~ alpha^2): finer bins in both coordinates.
          o.cos_theta_bins = 200;
          o.phi_bins = 400;
          o.sample_count = 1000000;
        }
        auto r = test::bsdf_chi2_test(*b, si, wo, o);
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_LE(r.pdf_integral, 1.0 + 1e-2) << o.name;
      }
    }
  }
}

TEST(RoughConductor, SampleWeightIsEvalOverPdf) {
  SurfaceInteraction si;
  for (MicrofacetType t : kTypes) {
    for (Alphas a : kAlphas) {
      auto b = make(t, a, "Cu");
      Pcg32 rng(11);
      for (float deg : kAngles) {
        Vec3 wo = direction(deg);
        for (int i = 0; i < 300; ++i) {
          BsdfSample bs;
          if (!b->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
          ASSERT_GT(bs.wi.z, 0.f);
          EXPECT_FALSE(bs.delta);
          float pdf = b->pdf(si, wo, bs.wi);
          EXPECT_NEAR(bs.pdf, pdf, 1e-3f * pdf + 1e-5f);
          Rgb ratio = b->eval(si, wo, bs.wi) / pdf;
          for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(bs.weight[c], ratio[c], 2e-3f * ratio[c] + 1e-5f) << type_name(t) << " " << a.u;
        }
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

TEST(RoughConductor, TexturedAlphaIsEvaluatedAtTheHit) {
  auto textured = make_roughconductor_bsdf(MicrofacetType::Ggx, std::make_shared<SplitTexture>(), nullptr,
                                           *lookup_metal("Cu"), constant(1.f));
  auto smooth = make(MicrofacetType::Ggx, {0.1f, 0.1f}, "Cu");
  auto rough = make(MicrofacetType::Ggx, {0.6f, 0.6f}, "Cu");
  SurfaceInteraction left, right;
  left.uv = Vec2(0.2f, 0.5f);
  right.uv = Vec2(0.8f, 0.5f);
  Vec3 wo = direction(30.f), wi = direction(35.f, 0.7f + kPi);
  EXPECT_EQ(textured->eval(left, wo, wi), smooth->eval(left, wo, wi));
  EXPECT_EQ(textured->eval(right, wo, wi), rough->eval(right, wo, wi));
  EXPECT_EQ(textured->pdf(right, wo, wi), rough->pdf(right, wo, wi));
  EXPECT_NE(textured->eval(left, wo, wi), textured->eval(right, wo, wi));
}

TEST(RoughConductor, OneSided) {
  SurfaceInteraction si;
  auto b = make(MicrofacetType::Ggx, {0.3f, 0.3f});
  Vec3 wo = direction(30.f), wi = direction(40.f, 3.5f);
  EXPECT_FALSE(b->eval(si, wo, wi).is_black());
  EXPECT_TRUE(b->eval(si, wo, Vec3(wi.x, wi.y, -wi.z)).is_black());
  EXPECT_TRUE(b->eval(si, Vec3(wo.x, wo.y, -wo.z), wi).is_black());
  EXPECT_EQ(b->pdf(si, Vec3(wo.x, wo.y, -wo.z), wi), 0.f);
  BsdfSample bs;
  EXPECT_FALSE(b->sample(si, Vec3(wo.x, wo.y, -wo.z), 0.5f, {0.3f, 0.7f}, bs));
}

// Directional albedo of a perfect reflector (F = 1): the Monte Carlo mean of the sample weights.
// Single scattering loses energy to masking as roughness grows (values printed as a table); it must
// never exceed 1 beyond noise, and must be nearly 1 for smooth surfaces seen from above.
TEST(RoughConductor, WhiteFurnaceAlbedo) {
  SurfaceInteraction si;
  const float alphas[] = {0.05f, 0.1f, 0.2f, 0.3f, 0.5f, 0.7f, 1.f};
  const int n = 200000;
  for (MicrofacetType t : kTypes) {
    std::printf("[furnace] %-8s theta_o:", type_name(t));
    for (float deg : kAngles) std::printf("  %6.0f", deg);
    std::printf("\n");
    for (float alpha : alphas) {
      auto b = make(t, {alpha, alpha}, "none");
      std::printf("[furnace]   alpha %.2f:", alpha);
      for (float deg : kAngles) {
        Vec3 wo = direction(deg);
        Pcg32 rng(7);
        double sum = 0, sum2 = 0;
        for (int i = 0; i < n; ++i) {
          BsdfSample bs;
          double w = 0;
          if (b->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) w = bs.weight.g;
          sum += w;
          sum2 += w * w;
        }
        double mean = sum / n, stderr_ = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
        std::printf("  %6.4f", mean);
        // Beckmann's G1 is a rational approximation (< 0.35% error): allow 0.5% above 1.
        double tol = t == MicrofacetType::Ggx ? 1e-3 : 5e-3;
        if (t == MicrofacetType::Phong && alpha >= 0.5f) {
          // Mitsuba's Phong borrows Beckmann's G1 at the equivalent alpha; for rough lobes that
          // overestimates masking-free area and the albedo exceeds 1 near grazing (1.17 at alpha 1,
          // 85 degrees). Kept for fidelity to Mitsuba; bounded here so that a change is noticed.
          tol = 0.2;
        }
        EXPECT_LE(mean, 1.0 + tol + 4.0 * stderr_) << type_name(t) << " alpha " << alpha << " theta " << deg;
        if (alpha <= 0.1f && deg <= 45.f) {
          EXPECT_GT(mean, 0.98) << type_name(t) << " alpha " << alpha;
        }
      }
      std::printf("\n");
    }
  }
}

}  // namespace
}  // namespace tessera
