// Smooth plastic: chi-square of the diffuse lobe, the Fresnel-steered lobe choice, weights against
// eval/pdf, and energy (a white base under a clear coat reflects everything).
#include "tessera/bsdf/dielectric.h"
#include "tessera/bsdf/fresnel.h"
#include "tessera/core/frame.h"
#include "tessera/core/hash.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace tessera {
namespace {

std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }

const Vec3 kWo[] = {Vec3(0.f, 0.f, 1.f), normalize(Vec3(0.6f, -0.3f, 0.5f)), normalize(Vec3(-0.9f, 0.1f, 0.15f)),
                    normalize(Vec3(0.2f, 0.99f, 0.02f))};

// Mitsuba's lobe choice: F * s / (F * s + (1 - F) * (1 - s)), s = spec / (spec + diffuse) luminance.
float expected_p_spec(float f, float d, float s) {
  const float w = s / (d + s);
  return f * w / (f * w + (1 - f) * (1 - w));
}

TEST(Plastic, Chi2DiffuseLobeMatchesPdf) {
  test::Chi2Options o;
  o.test_count = 2 * 2 * 4;
  o.name = "plastic";
  o.sample_count = 400000;
  for (float eta : {1.49f, 2.0f}) {
    for (Rgb diffuse : {Rgb(0.5f), Rgb(0.9f, 0.2f, 0.1f)}) {
      auto bsdf = make_plastic_bsdf(eta, constant(diffuse), constant(Rgb(1.f)), false);
      for (Vec3 wo : kWo) {
        // Delta samples are not part of the density: they count as failed samples, which is why the
        // pdf integrates to 1 - P(specular) and the histogram is compared with exactly that.
        auto r = test::chi2_test(
            test::Chi2Sampler3([&](Vec2 u, float u1) -> test::Chi2Sample {
              SurfaceInteraction si;
              BsdfSample bs;
              if (!bsdf->sample(si, wo, u1, u, bs) || bs.delta) return {Vec3(), 0.f, false};
              return {bs.wi, bs.pdf, true};
            }),
            [&](Vec3 wi) {
              SurfaceInteraction si;
              return double(bsdf->pdf(si, wo, wi));
            },
            o);
        EXPECT_TRUE(r.passed) << "eta " << eta << " wo.z " << wo.z << "\n" << r.message;
        const float p_spec = expected_p_spec(fresnel_dielectric(wo.z, eta), diffuse.luminance(), 1.f);
        EXPECT_NEAR(r.pdf_integral, 1.0 - p_spec, 1e-2);
      }
    }
  }
}

TEST(Plastic, SpecularChoiceAndWeights) {
  const Rgb diffuse(0.6f, 0.3f, 0.2f), spec(0.9f);
  for (bool nonlinear : {false, true}) {
    auto bsdf = make_plastic_bsdf(1.5f, constant(diffuse), constant(spec), nonlinear);
    EXPECT_FALSE(bsdf->is_delta());
    SurfaceInteraction si;
    for (Vec3 wo : kWo) {
      const float f = fresnel_dielectric(wo.z, 1.5f);
      const float p_spec = expected_p_spec(f, diffuse.luminance(), spec.luminance());
      Pcg32 rng(11);
      int n_spec = 0;
      const int n = 20000;
      for (int i = 0; i < n; ++i) {
        BsdfSample bs;
        ASSERT_TRUE(bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs));
        if (bs.delta) {
          ++n_spec;
          EXPECT_EQ(bs.wi, Vec3(-wo.x, -wo.y, wo.z));
          EXPECT_NEAR(bs.pdf, p_spec, 1e-5f);
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], spec[c] * f / p_spec, 1e-5f);
        } else {
          EXPECT_GT(bs.wi.z, 0.f);
          EXPECT_NEAR(bs.pdf, bsdf->pdf(si, wo, bs.wi), 1e-5f * bs.pdf);
          const Rgb ratio = bsdf->eval(si, wo, bs.wi) / bs.pdf;
          for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], ratio[c], 1e-4f * ratio[c]);
        }
      }
      const double sigma = std::sqrt(p_spec * (1 - p_spec) / n);
      EXPECT_NEAR(double(n_spec) / n, p_spec, 4 * sigma + 1e-9) << "wo.z " << wo.z;
    }
    // One-sided.
    BsdfSample bs;
    EXPECT_FALSE(bsdf->sample(si, Vec3(0.f, 0.f, -1.f), 0.5f, {0.5f, 0.5f}, bs));
    EXPECT_TRUE(bsdf->eval(si, Vec3(0.f, 0.f, -1.f), Vec3(0.f, 0.f, 1.f)).is_black());
    EXPECT_TRUE(bsdf->eval(si, Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.6f, -0.8f)).is_black());
  }
}

// Mitsuba's diffuse term: rho / (1 - fdr_int) (linear) or rho / (1 - rho fdr_int) (nonlinear).
TEST(Plastic, EvalMatchesMitsubaFormula) {
  const float eta = 1.49f;
  const float fdr = fresnel_diffuse_reflectance(1.f / eta);
  const Vec3 wo = normalize(Vec3(0.3f, 0.2f, 0.9f)), wi = normalize(Vec3(-0.5f, 0.1f, 0.6f));
  const float k = kInvPi * wi.z / (eta * eta) * (1 - fresnel_dielectric(wo.z, eta)) * (1 - fresnel_dielectric(wi.z, eta));
  SurfaceInteraction si;
  const float rho = 0.7f;
  EXPECT_NEAR(make_plastic_bsdf(eta, constant(Rgb(rho)), constant(Rgb(1.f)), false)->eval(si, wo, wi).r,
              rho / (1 - fdr) * k, 1e-6f);
  EXPECT_NEAR(make_plastic_bsdf(eta, constant(Rgb(rho)), constant(Rgb(1.f)), true)->eval(si, wo, wi).r,
              rho / (1 - rho * fdr) * k, 1e-6f);
}

// Directional albedo (estimated from sample weights) over angles: <= 1, and == 1 for a white base
// under a clear coat (linear model): (1 - F)(1 - fdr_ext) / (eta^2 (1 - fdr_int)) + F = 1.
TEST(Plastic, AlbedoAtMostOneAndWhiteIsOne) {
  for (float eta : {1.2f, 1.49f, 2.0f}) {
    for (float rho : {1.f, 0.5f}) {
      for (bool nonlinear : {false, true}) {
        auto bsdf = make_plastic_bsdf(eta, constant(Rgb(rho)), constant(Rgb(1.f)), nonlinear);
        SurfaceInteraction si;
        for (float cos_o : {1.f, 0.7f, 0.3f, 0.05f}) {
          const Vec3 wo(std::sqrt(1 - cos_o * cos_o), 0.f, cos_o);
          Pcg32 rng(5);
          const int n = 100000;
          double sum = 0, sum2 = 0;
          for (int i = 0; i < n; ++i) {
            BsdfSample bs;
            double w = 0;
            if (bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) w = bs.weight.g;
            sum += w;
            sum2 += w * w;
          }
          const double mean = sum / n, se = std::sqrt(std::max(sum2 / n - mean * mean, 0.0) / n);
          EXPECT_LE(mean, 1.0 + 4 * se + 1e-4) << eta << " " << rho << " " << cos_o;
          if (rho == 1.f) {
            EXPECT_NEAR(mean, 1.0, 4 * se + 2e-4) << eta << " " << cos_o << " nonlinear " << nonlinear;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace tessera
