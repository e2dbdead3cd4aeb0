// Helpers shared by the bumpmap and normalmap tests: in-memory textures with known derivatives
// and a flat surface point whose frames are the identity.
#pragma once

#include "bsdf_test_util.h"
#include "tessera/bsdf/bumpmap.h"
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/diffuse.h"
#include "tessera/core/hash.h"
#include "tessera/texture/bitmap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iterator>
#include <memory>
#include <string>

namespace tessera::test {

/// A grey bitmap whose bilinear interpolation is exactly slope_u * u + slope_v * v away from the
/// outermost half texel (texel centres carry the plane's values; clamp beyond).
inline std::shared_ptr<BitmapTexture> ramp_texture(float slope_u, float slope_v, int w = 64, int h = 64,
                                                   UvMapping to_uv = {}) {
  Image im(w, h, 1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im.at(x, y, 0) = slope_u * (x + 0.5f) / float(w) + slope_v * (y + 0.5f) / float(h);
  return std::make_shared<BitmapTexture>(std::make_shared<const Image>(std::move(im)), WrapMode::Clamp,
                                         WrapMode::Clamp, TextureFilter::Bilinear, to_uv);
}

/// An RGB bitmap of one colour everywhere (a constant normal map).
inline std::shared_ptr<BitmapTexture> solid_rgb_texture(Rgb c, int w = 4, int h = 4) {
  Image im(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) im.set_rgb(x, y, c);
  return std::make_shared<BitmapTexture>(std::make_shared<const Image>(std::move(im)), WrapMode::Repeat,
                                         WrapMode::Repeat);
}

/// A point of the plane z = 0 parameterised by (u, v) = (x, y): every frame is the identity.
inline SurfaceInteraction flat_si(Vec2 uv = {0.4f, 0.6f}) {
  SurfaceInteraction si;
  si.ng = Vec3(0.f, 0.f, 1.f);
  si.uv = uv;
  si.wo = Vec3(0.f, 0.f, 1.f);
  return si;
}

inline std::shared_ptr<Bsdf> white_diffuse(float albedo = 1.f) {
  return make_diffuse_bsdf(std::make_shared<ConstantTexture>(Rgb(albedo)));
}

inline std::shared_ptr<Bsdf> rough_gold(float alpha = 0.3f) {
  return rough_metal("Au", MicrofacetType::Ggx, alpha);
}

/// Mean sample weight (failed samples count as 0) and its standard error: directional albedo.
inline void directional_albedo(const Bsdf& b, const SurfaceInteraction& si, Vec3 wo, int n, uint64_t seed,
                               double& mean, double& stderr_out) {
  Pcg32 rng(seed);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample bs;
    double w = 0;
    if (b.sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) w = bs.weight.g;
    sum += w;
    sum2 += w * w;
  }
  mean = sum / n;
  stderr_out = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
}

/// Polar angles of wo (degrees) at which both wrappers are tested, normal to near grazing.
inline constexpr float kAngles[] = {0.f, 30.f, 60.f, 80.f};

/// `wrapped` gives bit for bit what `nested` gives at `si` (eval, pdf and samples): a flat map must
/// not even round. Call through ASSERT_NO_FATAL_FAILURE.
inline void expect_flat_map_is_nested(const Bsdf& wrapped, const Bsdf& nested, const SurfaceInteraction& si,
                                      uint64_t seed) {
  Pcg32 rng(seed);
  for (int i = 0; i < 500; ++i) {
    Vec3 wo = direction_deg(85.f * rng.next_float(), 360.f * rng.next_float());
    Vec3 wi = direction_deg(85.f * rng.next_float(), 360.f * rng.next_float());
    EXPECT_EQ(wrapped.eval(si, wo, wi), nested.eval(si, wo, wi));
    EXPECT_EQ(wrapped.pdf(si, wo, wi), nested.pdf(si, wo, wi));
    float u1 = rng.next_float();
    Vec2 u2(rng.next_float(), rng.next_float());
    BsdfSample a, b;
    bool ok_a = wrapped.sample(si, wo, u1, u2, a), ok_b = nested.sample(si, wo, u1, u2, b);
    ASSERT_EQ(ok_a, ok_b);
    if (!ok_a) continue;
    EXPECT_EQ(a.wi, b.wi);
    EXPECT_EQ(a.pdf, b.pdf);
    EXPECT_EQ(a.weight, b.weight);
  }
}

/// Chi-square of `wrap(nested)` at flat_si() for a diffuse and a rough gold nested BSDF, wo at
/// kAngles. `wrap` must tilt the normal towards azimuth ~200 degrees: wo's azimuth 190 then keeps
/// it above the tilted normal even at 80 degrees.
template <class Wrap>
void expect_tilted_chi2_passes(Wrap wrap) {
  auto diffuse = white_diffuse(0.8f);
  auto gold = rough_gold(0.3f);
  SurfaceInteraction si = flat_si();
  const int tests = 2 * int(std::size(kAngles));
  for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
    auto wrapped = wrap(nested);
    for (float deg : kAngles) {
      Chi2Options o;
      o.test_count = tests;
      o.sample_count = 300000;
      o.name = std::string(nested == diffuse.get() ? "diffuse" : "roughconductor") + " theta_o " + std::to_string(deg);
      if (nested == gold.get()) {
        o.cos_theta_bins = 100;
        o.phi_bins = 200;
        o.sample_count = 1000000;
      }
      auto r = bsdf_chi2_test(*wrapped, si, direction_deg(deg, 190.f), o);
      EXPECT_TRUE(r.passed) << r.message;
      EXPECT_GT(r.valid_samples, o.sample_count / 2) << o.name;
    }
  }
}

/// Sample weights and pdfs of `wrap(nested)` against eval / pdf, for the nested BSDFs and wo of
/// expect_tilted_chi2_passes; every sample must stay above the surface.
template <class Wrap>
void expect_tilted_weights_are_eval_over_pdf(Wrap wrap, uint64_t seed) {
  SurfaceInteraction si = flat_si();
  auto diffuse = white_diffuse(0.8f);
  auto gold = rough_gold(0.3f);
  for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
    auto wrapped = wrap(nested);
    Pcg32 rng(seed);
    int checked = 0;
    for (float deg : kAngles) {
      Vec3 wo = direction_deg(deg, 190.f);
      for (int i = 0; i < 300; ++i) {
        BsdfSample bs;
        if (!wrapped->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) continue;
        ASSERT_GT(bs.wi.z, 0.f);
        float pdf = wrapped->pdf(si, wo, bs.wi);
        ASSERT_GT(pdf, 0.f);
        EXPECT_NEAR(bs.pdf, pdf, 1e-3f * pdf);
        Rgb ratio = wrapped->eval(si, wo, bs.wi) / pdf;
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(bs.weight[c], ratio[c], 2e-3f * ratio[c] + 1e-6f);
        ++checked;
      }
    }
    EXPECT_GT(checked, 600);
  }
}

/// Directional albedo of `b` at flat_si() for wo at kAngles (azimuth `phi_deg`) is `expected`
/// and, within the noise, at most 1.
inline void expect_clipped_lobe_albedo(const Bsdf& b, float phi_deg, uint64_t seed, double expected) {
  SurfaceInteraction si = flat_si();
  for (float deg : kAngles) {
    double mean, err;
    directional_albedo(b, si, direction_deg(deg, phi_deg), 200000, seed, mean, err);
    EXPECT_NEAR(mean, expected, 4 * err + 1e-3) << deg;
    EXPECT_LE(mean, 1.0 + 4 * err);
  }
}

/// eval, pdf and samples of `b` at `si` stay finite (and samples unit) over `n` random pairs of
/// directions on the whole sphere.
inline void expect_finite_everywhere(const Bsdf& b, const SurfaceInteraction& si, uint64_t seed, int n,
                                     const char* what) {
  Pcg32 rng(seed);
  for (int i = 0; i < n; ++i) {
    Vec3 wo = direction_deg(180.f * rng.next_float(), 360.f * rng.next_float());
    Vec3 wi = direction_deg(180.f * rng.next_float(), 360.f * rng.next_float());
    ASSERT_TRUE(b.eval(si, wo, wi).is_finite()) << what;
    float pdf = b.pdf(si, wo, wi);
    ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0.f) << what;
    BsdfSample bs;
    if (b.sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) {
      ASSERT_TRUE(is_finite(bs.wi) && std::isfinite(bs.pdf) && bs.weight.is_finite()) << what;
      ASSERT_NEAR(length(bs.wi), 1.f, 1e-4f) << what;
    }
  }
}

}  // namespace tessera::test
