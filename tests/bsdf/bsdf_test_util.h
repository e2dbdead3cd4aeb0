// Helpers shared by the BSDF tests.
#pragma once

#include "support/chi2.h"
#include "tessera/bsdf/conductor.h"
#include "tessera/core/hash.h"
#include "tessera/core/ray.h"
#include "tessera/render/bsdf.h"
#include "tessera/core/vec.h"
#include "tessera/render/texture.h"
#include "tessera/scene/load_context.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace tessera::test {

/// Unit direction in the local shading frame from polar angle theta and azimuth phi, in degrees.
inline Vec3 direction_deg(float theta_deg, float phi_deg) {
  float t = theta_deg * kPi / 180.f, p = phi_deg * kPi / 180.f;
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

/// Chi-square test of `bsdf.sample` against `bsdf.pdf` for the outgoing direction `wo` at `si`.
inline Chi2Result bsdf_chi2_test(const Bsdf& bsdf, const SurfaceInteraction& si, Vec3 wo, const Chi2Options& o) {
  return chi2_test(
      Chi2Sampler3([&](Vec2 u, float u1) {
        BsdfSample bs;
        if (!bsdf.sample(si, wo, u1, u, bs)) return Chi2Sample{Vec3(), 0.f, false};
        return Chi2Sample{bs.wi, bs.pdf, true};
      }),
      [&](Vec3 wi) { return double(bsdf.pdf(si, wo, wi)); }, o);
}

inline std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }
inline std::shared_ptr<Texture> constant(float c) { return constant(Rgb(c)); }

/// Outgoing directions from normal to grazing incidence (cos theta 1, 0.6, 0.16, 0.03), each at
/// another azimuth so that anisotropy bugs show.
inline const Vec3 kWo[] = {Vec3(0.f, 0.f, 1.f), normalize(Vec3(0.6f, -0.3f, 0.5f)),
                           normalize(Vec3(-0.9f, 0.1f, 0.15f)), normalize(Vec3(0.2f, 0.99f, 0.03f))};

inline std::shared_ptr<Bsdf> rough_metal(const char* name, MicrofacetType type, float alpha) {
  return make_roughconductor_bsdf(type, constant(alpha), nullptr, *lookup_metal(name), constant(1.f));
}

/// Layered BSDFs: the cosine of a direction of cosine `c` refracted into a layer of relative IOR
/// `eta` (Snell).
inline float cos_inside(float c, float eta) { return std::sqrt(1.f - (1.f - c * c) / (eta * eta)); }

/// Layered BSDFs: absorption (`sigma_a` over thickness `d`, under an interface of relative IOR
/// `eta`) scales `clear`'s value by exp(-sigma_a d (1/cos_o' + 1/cos_i')) per channel, cos' the
/// refracted cosines. `also_clear`, when not null, must give `clear`'s value exactly.
inline void expect_absorption_along_refracted(const Bsdf& clear, const Bsdf& tinted, const Bsdf* also_clear,
                                              float eta, float d, Rgb sigma_a) {
  SurfaceInteraction si;
  for (Vec3 wo : kWo) {
    for (float theta : {0.f, 40.f, 80.f}) {
      const Vec3 wi = direction_deg(theta, 170.f);
      const Rgb a = clear.eval(si, wo, wi), b = tinted.eval(si, wo, wi);
      ASSERT_GT(a.g, 0.f);
      const float len = d * (1 / cos_inside(wo.z, eta) + 1 / cos_inside(wi.z, eta));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(b[c] / a[c], std::exp(-sigma_a[c] * len), 1e-4f) << wo.z << " " << theta;
      if (also_clear) {
        EXPECT_EQ(also_clear->eval(si, wo, wi), a);
      }
    }
  }
}

/// `body` inside a Mitsuba 0.6 <scene>, loaded as if read from `virtual_path` (which error messages
/// name); unsupported parameters are listed rather than fatal, so tests can assert the list empty.
inline LoadResult load_mitsuba06(const std::string& body, const std::string& virtual_path) {
  LoadOptions options;
  options.allow_unsupported = true;
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", virtual_path), options);
}

struct AlbedoEstimate {
  double mean = 0, se = 0;
};
/// Mean green sample weight (directional albedo) at a default interaction and its standard error.
/// The seed is fixed so that estimates of different BSDFs share their random numbers.
inline AlbedoEstimate albedo(const Bsdf& bsdf, Vec3 wo, int n = 100000) {
  Pcg32 rng(17);
  SurfaceInteraction si;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample bs;
    const float u1 = rng.next_float();
    const Vec2 u2(rng.next_float(), rng.next_float());
    if (!bsdf.sample(si, wo, u1, u2, bs)) continue;
    sum += bs.weight.g;
    sum2 += double(bs.weight.g) * bs.weight.g;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(sum2 / n - mean * mean, 0.0) / n)};
}

/// Chi-square of `bsdf` at a default interaction, one of `test_count` tests. Narrow lobes
/// (alpha < 0.1) and lobes squeezed against the horizon (wo.z < 0.2) fill few of the default
/// bins, so they get finer bins and more samples.
inline Chi2Result lobe_chi2_test(const Bsdf& bsdf, Vec3 wo, float alpha, int test_count, const std::string& name) {
  Chi2Options o;
  o.test_count = test_count;
  o.name = name;
  o.sample_count = 200000;
  if (alpha < 0.1f || wo.z < 0.2f) {
    o.cos_theta_bins = 200;
    o.phi_bins = 400;
    o.sample_count = 600000;
  }
  SurfaceInteraction si;
  return bsdf_chi2_test(bsdf, si, wo, o);
}

/// For a BSDF without delta lobes: 4000 samples cycling through kWo (seed 3) whose weight and pdf
/// match eval / pdf. `ok` counts the samples that succeeded; call through ASSERT_NO_FATAL_FAILURE.
inline void expect_weight_is_eval_over_pdf(const Bsdf& bsdf, int& ok) {
  Pcg32 rng(3);
  SurfaceInteraction si;
  ok = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3 wo = kWo[i % 4];
    BsdfSample bs;
    if (!bsdf.sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
    ++ok;
    ASSERT_FALSE(bs.delta);
    const float pdf = bsdf.pdf(si, wo, bs.wi);
    const Rgb f = bsdf.eval(si, wo, bs.wi);
    EXPECT_NEAR(bs.pdf, pdf, 1e-4f * pdf);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], f[c] / pdf, 1e-4f * f[c] / pdf + 1e-7f);
  }
}

/// sample(), eval() both ways and pdf() stay finite for wo on and just off the horizon (both
/// sides) and wi within 0.01 degrees of it. `rng` runs on across calls: one stream per test.
inline void expect_finite_at_grazing(const Bsdf& bsdf, Pcg32& rng) {
  SurfaceInteraction si;
  for (float z : {0.f, 1e-7f, 1e-4f, -1e-4f}) {
    const Vec3 wo = normalize(Vec3(std::sqrt(1.f - z * z), 0.f, z));
    for (int i = 0; i < 2000; ++i) {
      BsdfSample bs;
      if (bsdf.sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) {
        EXPECT_TRUE(bs.weight.is_finite() && std::isfinite(bs.pdf) && is_finite(bs.wi)) << z;
      }
      const Vec3 wi = direction_deg(89.99f + 0.01f * rng.next_float(), 360.f * rng.next_float());
      EXPECT_TRUE(bsdf.eval(si, wo, wi).is_finite()) << z;
      EXPECT_TRUE(bsdf.eval(si, wi, wo).is_finite()) << z;
      EXPECT_TRUE(std::isfinite(bsdf.pdf(si, wo, wi))) << z;
    }
  }
}

}  // namespace tessera::test
