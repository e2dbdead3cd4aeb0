// dielectric and thindielectric: delta lobes, so instead of chi-square the discrete choice
// frequencies (against F), exact mirror/Snell directions, weights, and energy.
#include "tessera/bsdf/dielectric.h"
#include "tessera/bsdf/fresnel.h"
#include "tessera/core/frame.h"
#include "tessera/core/hash.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>

namespace tessera {
namespace {

std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }

// Directions from normal to grazing, on both sides of the surface.
std::vector<Vec3> test_directions() {
  std::vector<Vec3> out;
  for (float cos_t : {1.f, 0.9f, 0.6f, 0.3f, 0.1f, 0.02f}) {
    const float s = std::sqrt(1.f - cos_t * cos_t);
    for (float sign : {1.f, -1.f}) out.push_back(Vec3(s * 0.8f, s * -0.6f, sign * cos_t));
  }
  return out;
}

// Frequency of the reflection choice is F within 4 binomial standard deviations (and never off).
void expect_choice_frequency(const Bsdf& bsdf, Vec3 wo, double p_reflect) {
  SurfaceInteraction si;
  Pcg32 rng(7);
  const int n = 20000;
  int reflected = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample bs;
    ASSERT_TRUE(bsdf.sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs));
    ASSERT_TRUE(bs.delta);
    if (bs.wi.z * wo.z > 0.f) ++reflected;
  }
  const double sigma = std::sqrt(p_reflect * (1 - p_reflect) / n);
  EXPECT_NEAR(double(reflected) / n, p_reflect, 4 * sigma + 1e-9) << "wo.z " << wo.z;
}

TEST(Dielectric, ChoiceProbabilitiesAreFresnel) {
  for (float eta : {1.5046f, 1.333f, 2.419f}) {
    auto bsdf = make_dielectric_bsdf(eta, constant(Rgb(1.f)), constant(Rgb(1.f)));
    for (Vec3 wo : test_directions()) expect_choice_frequency(*bsdf, wo, fresnel_dielectric(wo.z, eta));
  }
}

TEST(Dielectric, DirectionsWeightsAndEnergy) {
  const Rgb refl(0.9f, 0.8f, 0.7f), trans(0.6f, 0.5f, 0.4f);
  for (float eta : {1.5046f, 1.333f, 2.419f}) {
    auto bsdf = make_dielectric_bsdf(eta, constant(refl), constant(trans));
    auto white = make_dielectric_bsdf(eta, constant(Rgb(1.f)), constant(Rgb(1.f)));
    EXPECT_TRUE(bsdf->is_delta());
    SurfaceInteraction si;
    for (Vec3 wo : test_directions()) {
      const float f = fresnel_dielectric(wo.z, eta);
      BsdfSample r, t;
      ASSERT_TRUE(bsdf->sample(si, wo, 0.f, {0.5f, 0.5f}, r));  // u1 = 0 < F: reflection if F > 0
      ASSERT_TRUE(bsdf->sample(si, wo, 0.999999f, {0.5f, 0.5f}, t));
      // Reflection: exact mirror, probability F, weight the reflectance (F / F).
      EXPECT_EQ(r.wi.x, -wo.x);
      EXPECT_EQ(r.wi.y, -wo.y);
      EXPECT_EQ(r.wi.z, wo.z);
      EXPECT_FLOAT_EQ(r.pdf, f);
      EXPECT_EQ(r.weight, refl);
      EXPECT_EQ(r.eta, 1.f);
      if (f >= 0.999999f) {  // total internal reflection: always reflected
        EXPECT_EQ(t.wi.z, wo.z);
        continue;
      }
      // Refraction: other side, unit, Snell's law n_o sin_o = n_i sin_i, in the plane of incidence.
      const bool entering = wo.z > 0.f;
      const float n_o = entering ? 1.f : eta, n_i = entering ? eta : 1.f;
      EXPECT_LT(t.wi.z * wo.z, 0.f);
      EXPECT_NEAR(length(t.wi), 1.f, 1e-5f);
      const float sin_o = std::sqrt(wo.x * wo.x + wo.y * wo.y), sin_i = std::sqrt(t.wi.x * t.wi.x + t.wi.y * t.wi.y);
      EXPECT_NEAR(n_o * sin_o, n_i * sin_i, 1e-5f);
      EXPECT_NEAR(cross(Vec3(wo.x, wo.y, 0.f), Vec3(t.wi.x, t.wi.y, 0.f)).z, 0.f, 1e-6f);
      if (sin_o > 0.f) {
        EXPECT_LT(wo.x * t.wi.x + wo.y * t.wi.y, 0.f);  // continues across the normal
      }
      EXPECT_FLOAT_EQ(t.pdf, 1.f - f);
      // Radiance scaling (n_o / n_i)^2, and eta reported as n_i / n_o.
      const float scale = (n_o / n_i) * (n_o / n_i);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(t.weight[c], trans[c] * scale, 1e-6f);
      EXPECT_NEAR(t.eta, n_i / n_o, 1e-6f);
      // Energy with white textures: the expected throughput before the radiance scaling,
      // pdf_r * w_r + pdf_t * w_t / scale, is exactly R + T = 1.
      BsdfSample wr, wt;
      ASSERT_TRUE(white->sample(si, wo, 0.f, {}, wr));
      ASSERT_TRUE(white->sample(si, wo, 0.999999f, {}, wt));
      const float total = (f > 0.f ? wr.pdf * wr.weight.g : 0.f) + wt.pdf * wt.weight.g / scale;
      EXPECT_NEAR(total, 1.f, 1e-6f);
      // The reversed path (arriving along -t.wi) refracts back to wo, and cancels the scaling.
      BsdfSample back;
      ASSERT_TRUE(white->sample(si, t.wi, 0.999999f, {}, back));
      EXPECT_NEAR(back.wi.x, wo.x, 1e-4f);
      EXPECT_NEAR(back.wi.z, wo.z, 1e-4f);
      EXPECT_NEAR(back.weight.g * wt.weight.g, 1.f, 1e-5f);
    }
  }
}

TEST(Dielectric, TotalInternalReflectionFromInside) {
  auto bsdf = make_dielectric_bsdf(1.5f, constant(Rgb(1.f)), constant(Rgb(1.f)));
  SurfaceInteraction si;
  Vec3 wo = normalize(Vec3(0.9f, 0.f, -0.3f));  // beyond the critical angle (cos 0.745)
  for (float u : {0.f, 0.5f, 0.999f}) {
    BsdfSample bs;
    ASSERT_TRUE(bsdf->sample(si, wo, u, {}, bs));
    EXPECT_EQ(bs.wi.z, wo.z);
    EXPECT_EQ(bs.pdf, 1.f);
    EXPECT_EQ(bs.weight, Rgb(1.f));
  }
}

TEST(Dielectric, EvalAndPdfAreZero) {
  auto bsdf = make_dielectric_bsdf(1.5f, constant(Rgb(1.f)), constant(Rgb(1.f)));
  SurfaceInteraction si;
  Vec3 wo = normalize(Vec3(0.3f, 0.2f, 0.9f));
  EXPECT_TRUE(bsdf->eval(si, wo, Vec3(-wo.x, -wo.y, wo.z)).is_black());
  EXPECT_EQ(bsdf->pdf(si, wo, Vec3(-wo.x, -wo.y, wo.z)), 0.f);
}

TEST(ThinDielectric, ChoiceDirectionsAndEnergy) {
  for (float eta : {1.5f, 1.333f}) {
    auto bsdf = make_thindielectric_bsdf(eta, constant(Rgb(1.f)), constant(Rgb(1.f)));
    EXPECT_TRUE(bsdf->is_delta());
    SurfaceInteraction si;
    for (Vec3 wo : test_directions()) {
      const float r1 = fresnel_dielectric(std::abs(wo.z), eta), t1 = 1.f - r1;
      // Sum of the inter-reflection series, term by term.
      double r_series = r1, tt = double(t1) * t1 * r1;
      for (int k = 0; k < 2000; ++k, tt *= double(r1) * r1) r_series += tt;
      const double r = r1 < 1.f ? r_series : 1.0;
      BsdfSample a, b;
      ASSERT_TRUE(bsdf->sample(si, wo, 0.f, {}, a));
      ASSERT_TRUE(bsdf->sample(si, wo, 0.999999f, {}, b));
      EXPECT_EQ(a.wi, Vec3(-wo.x, -wo.y, wo.z));
      EXPECT_NEAR(a.pdf, r, 1e-5);
      EXPECT_EQ(a.weight, Rgb(1.f));
      if (r > 0.999999) continue;
      EXPECT_EQ(b.wi, -wo);
      EXPECT_NEAR(b.pdf, 1.0 - r, 1e-5);
      EXPECT_EQ(b.weight, Rgb(1.f));
      EXPECT_EQ(b.eta, 1.f);
      EXPECT_NEAR(a.pdf + b.pdf, 1.f, 1e-6f);  // R + T == 1
      EXPECT_GE(a.pdf, r1);                     // the slab reflects more than one face
    }
    for (Vec3 wo : test_directions()) {
      float r1 = fresnel_dielectric(std::abs(wo.z), eta);
      expect_choice_frequency(*bsdf, wo, r1 + (1 - r1) * (1 - r1) * r1 / (1 - r1 * r1));
    }
  }
}

}  // namespace
}  // namespace tessera
