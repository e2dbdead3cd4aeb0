// blendbsdf: chi-square of sample() against pdf() for blends of rough lobes over weights, roughness
// and incidence; the weight-driven choice of a delta component; weights against eval/pdf; energy;
// the limits weight 0 / 1 (exactly the components); opacity forwarding; grazing angles; XML loading.
#include "tessera/bsdf/blendbsdf.h"

#include "bsdf_test_util.h"
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/diffuse.h"
#include "tessera/bsdf/roughdielectric.h"
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

std::shared_ptr<Bsdf> rough_gold(MicrofacetType type, float alpha) { return test::rough_metal("Au", type, alpha); }

// The shared estimate's green channel, rounded to float as the assertions below were written for.
float albedo_g(const Bsdf& bsdf, Vec3 wo) { return float(test::albedo(bsdf, wo).mean); }

// Test-only texture: a weight that differs between two halves of the uv square.
class HalfTexture final : public Texture {
 public:
  HalfTexture(float left, float right) : left_(left), right_(right) {}
  Rgb eval(const SurfaceInteraction& si) const override { return Rgb(si.uv.x < 0.5f ? left_ : right_); }
  Rgb mean() const override { return Rgb(0.5f * (left_ + right_)); }

 private:
  float left_, right_;
};

// Test-only BSDF with a mask-like opacity.
class OpaqueFraction final : public Bsdf {
 public:
  explicit OpaqueFraction(float opacity) : opacity_(opacity) {}
  Rgb eval(const SurfaceInteraction&, Vec3, Vec3) const override { return {}; }
  float pdf(const SurfaceInteraction&, Vec3, Vec3) const override { return 0.f; }
  bool sample(const SurfaceInteraction&, Vec3, float, Vec2, BsdfSample&) const override { return false; }
  bool has_opacity() const override { return true; }
  float opacity(const SurfaceInteraction&) const override { return opacity_; }

 private:
  float opacity_;
};

TEST(BlendBsdf, Chi2SampleMatchesPdf) {
  struct Case {
    std::shared_ptr<Bsdf> a, b;
    float weight;
    float alpha;
  };
  std::vector<Case> cases;
  for (float alpha : {0.05f, 0.3f, 1.f}) {
    cases.push_back({make_diffuse_bsdf(constant(0.5f)), rough_gold(MicrofacetType::Beckmann, alpha), 0.5f, alpha});
    // The transmissive component covers the lower hemisphere. Its own narrow lobes at the pole and
    // GGX's step at the grazing refraction edge need special bins (roughdielectric_test.cpp), so it
    // is kept at a moderate Beckmann roughness here.
    cases.push_back({make_roughdielectric_bsdf(MicrofacetType::Beckmann, constant(std::max(alpha, 0.3f)), nullptr,
                                               1.5f, constant(1.f), constant(1.f)),
                     rough_gold(MicrofacetType::Ggx, alpha), 0.3f, alpha});
    cases.push_back({make_roughplastic_bsdf(MicrofacetType::Phong, alpha, 1.33f, constant(0.5f), constant(1.f), false),
                     make_diffuse_bsdf(constant(0.8f)), 0.8f, alpha});
  }
  const int test_count = int(cases.size() * std::size(kWo));
  for (const Case& c : cases) {
    auto bsdf = make_blend_bsdf(constant(c.weight), c.a.get(), c.b.get());
    for (Vec3 wo : kWo) {
      auto r = test::lobe_chi2_test(*bsdf, wo, c.alpha, test_count, "blendbsdf");
      EXPECT_TRUE(r.passed) << "weight " << c.weight << " alpha " << c.alpha << " wo.z " << wo.z << "\n" << r.message;
    }
  }
}

// A delta component is chosen with the probability of its weight; its sample keeps its own weight.
TEST(BlendBsdf, DeltaComponentChoice) {
  auto mirror = make_conductor_bsdf(*lookup_metal("none"), constant(0.9f));
  auto diffuse = make_diffuse_bsdf(constant(0.5f));
  SurfaceInteraction si;
  for (float w : {0.f, 0.25f, 0.7f, 1.f}) {
    auto bsdf = make_blend_bsdf(constant(w), diffuse.get(), mirror.get());
    EXPECT_FALSE(bsdf->is_delta());  // a blend with a diffuse part is never all-delta
    for (Vec3 wo : kWo) {
      Pcg32 rng(23);
      const int n = 20000;
      int n_delta = 0;
      for (int i = 0; i < n; ++i) {
        BsdfSample bs;
        ASSERT_TRUE(bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs));
        if (bs.delta) {
          ++n_delta;
          EXPECT_NEAR(bs.pdf, w, 1e-6f);
          EXPECT_NEAR(bs.wi.z, wo.z, 1e-6f);
          EXPECT_NEAR(bs.weight.g, 0.9f, 1e-5f);
        } else {
          EXPECT_NEAR(bs.pdf, (1.f - w) * bs.wi.z * kInvPi, 1e-5f);
          EXPECT_NEAR(bs.weight.g, 0.5f, 1e-5f);
        }
      }
      const double sigma = std::sqrt(w * (1 - w) / n);
      EXPECT_NEAR(double(n_delta) / n, w, 4 * sigma + 1e-9) << "weight " << w << " wo.z " << wo.z;
    }
  }
  auto both = make_blend_bsdf(constant(0.5f), mirror.get(), mirror.get());
  EXPECT_TRUE(both->is_delta());
}

TEST(BlendBsdf, WeightIsEvalOverPdf) {
  auto a = rough_gold(MicrofacetType::Ggx, 0.2f);
  auto b = make_roughdielectric_bsdf(MicrofacetType::Beckmann, constant(0.4f), nullptr, 1.5f, constant(1.f),
                                     constant(1.f));
  auto bsdf = make_blend_bsdf(constant(0.6f), a.get(), b.get());
  int ok = 0;
  ASSERT_NO_FATAL_FAILURE(test::expect_weight_is_eval_over_pdf(*bsdf, ok));
  EXPECT_GT(ok, 3000);  // grazing refractions fail now and then
}

// Weight 0 is the first BSDF, 1 the second, bit for bit (eval, pdf and samples).
TEST(BlendBsdf, WeightZeroOrOneIsTheComponent) {
  auto a = make_roughplastic_bsdf(MicrofacetType::Beckmann, 0.2f, 1.5f, constant(Rgb(0.7f, 0.2f, 0.1f)),
                                  constant(1.f), false);
  auto b = rough_gold(MicrofacetType::Ggx, 0.3f);
  SurfaceInteraction si;
  for (float w : {0.f, 1.f}) {
    auto bsdf = make_blend_bsdf(constant(w), a.get(), b.get());
    const Bsdf& ref = w == 0.f ? *a : *b;
    Pcg32 rng(9);
    for (int i = 0; i < 2000; ++i) {
      const Vec3 wo = kWo[i % 3];
      const float u1 = rng.next_float();
      const Vec2 u2(rng.next_float(), rng.next_float());
      BsdfSample s1, s2;
      const bool ok1 = bsdf->sample(si, wo, u1, u2, s1), ok2 = ref.sample(si, wo, u1, u2, s2);
      ASSERT_EQ(ok1, ok2);
      if (!ok1) continue;
      EXPECT_EQ(s1.wi, s2.wi);
      EXPECT_NEAR(s1.pdf, s2.pdf, 1e-6f * s2.pdf);
      EXPECT_NEAR(s1.weight.r, s2.weight.r, 1e-5f * s2.weight.r + 1e-8f);
      EXPECT_EQ(bsdf->eval(si, wo, s2.wi), ref.eval(si, wo, s2.wi));
      EXPECT_EQ(bsdf->pdf(si, wo, s2.wi), ref.pdf(si, wo, s2.wi));
    }
  }
}

// White furnace: a blend of lossless-at-most components reflects at most everything; a blend of
// a white Lambertian and a perfect mirror reflects exactly everything.
TEST(BlendBsdf, WhiteFurnace) {
  auto white = make_diffuse_bsdf(constant(1.f));
  auto mirror = make_conductor_bsdf(*lookup_metal("none"), constant(1.f));
  auto rough_mirror = make_roughconductor_bsdf(MicrofacetType::Beckmann, constant(0.3f), nullptr,
                                               *lookup_metal("none"), constant(1.f));
  auto exact = make_blend_bsdf(constant(0.4f), white.get(), mirror.get());
  auto lossy = make_blend_bsdf(constant(0.5f), white.get(), rough_mirror.get());
  for (Vec3 wo : kWo) {
    EXPECT_NEAR(albedo_g(*exact, wo), 1.f, 1e-4f) << wo.z;
    const float a = albedo_g(*lossy, wo);
    EXPECT_LE(a, 1.005f) << wo.z;
    EXPECT_GT(a, 0.9f) << wo.z;  // Beckmann 0.3 loses < 10% (docs/microfacet-albedo.md)
  }
}

TEST(BlendBsdf, TexturedWeightAndOpacity) {
  auto a = make_diffuse_bsdf(constant(0.2f));
  auto b = make_diffuse_bsdf(constant(0.8f));
  auto bsdf = make_blend_bsdf(std::make_shared<HalfTexture>(0.25f, 1.5f), a.get(), b.get());  // 1.5 clamps to 1
  SurfaceInteraction left, right;
  left.uv = Vec2(0.1f, 0.5f);
  right.uv = Vec2(0.9f, 0.5f);
  const Vec3 w(0.f, 0.f, 1.f);
  EXPECT_NEAR(bsdf->eval(left, w, w).g, (0.75f * 0.2f + 0.25f * 0.8f) * kInvPi, 1e-6f);
  EXPECT_NEAR(bsdf->eval(right, w, w).g, 0.8f * kInvPi, 1e-6f);
  EXPECT_FALSE(bsdf->has_opacity());
  EXPECT_EQ(bsdf->opacity(left), 1.f);

  OpaqueFraction masked(0.2f);
  auto blend = make_blend_bsdf(constant(0.25f), &masked, b.get());
  EXPECT_TRUE(blend->has_opacity());
  EXPECT_NEAR(blend->opacity(left), 0.75f * 0.2f + 0.25f * 1.f, 1e-6f);
}

TEST(BlendBsdf, FiniteAtGrazingAngles) {
  auto a = rough_gold(MicrofacetType::Ggx, 0.05f);
  auto b = make_roughdielectric_bsdf(MicrofacetType::Beckmann, constant(0.5f), nullptr, 1.5f, constant(1.f),
                                     constant(1.f));
  auto bsdf = make_blend_bsdf(constant(0.5f), a.get(), b.get());
  SurfaceInteraction si;
  Pcg32 rng(31);
  for (float z : {0.f, 1e-7f, 1e-4f, -1e-4f}) {
    const Vec3 wo = normalize(Vec3(std::sqrt(1.f - z * z), 0.f, z));
    for (int i = 0; i < 2000; ++i) {
      BsdfSample bs;
      if (bsdf->sample(si, wo, rng.next_float(), {rng.next_float(), rng.next_float()}, bs)) {
        EXPECT_TRUE(bs.weight.is_finite() && std::isfinite(bs.pdf)) << z;
      }
      const Vec3 wi = test::direction_deg(89.999f + 0.001f * rng.next_float(), 360.f * rng.next_float());
      EXPECT_TRUE(bsdf->eval(si, wo, wi).is_finite()) << z;
      EXPECT_TRUE(std::isfinite(bsdf->pdf(si, wo, wi))) << z;
    }
  }
}

LoadResult load_06(const std::string& body) { return test::load_mitsuba06(body, "mem/blend.xml"); }

TEST(BlendBsdf, LoadsMitsuba06Xml) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="blendbsdf">
    <float name="weight" value="0.3"/>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf>
    <bsdf type="conductor"><string name="material" value="Au"/></bsdf></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ASSERT_FALSE(r.scene->shapes.empty());
  const Bsdf& loaded = *r.scene->shapes.at(0)->bsdf;
  EXPECT_FALSE(loaded.is_delta());
  SurfaceInteraction si;
  const Vec3 wo = kWo[1], wi = normalize(Vec3(-0.4f, 0.2f, 0.7f));
  EXPECT_NEAR(loaded.eval(si, wo, wi).b, 0.7f * 0.6f * kInvPi * wi.z, 1e-6f);
  EXPECT_NEAR(loaded.pdf(si, wo, wi), 0.7f * kInvPi * wi.z, 1e-6f);

  // A textured weight; the default weight is 0.5.
  r = load_06(R"(<shape type="sphere"><bsdf type="blendbsdf">
    <texture type="checkerboard" name="weight"/>
    <bsdf type="diffuse"/><bsdf type="roughplastic"/></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  r = load_06(R"(<shape type="sphere"><bsdf type="blendbsdf">
    <bsdf type="diffuse"><float name="reflectance" value="0"/></bsdf>
    <bsdf type="diffuse"><float name="reflectance" value="1"/></bsdf></bsdf></shape>)");
  EXPECT_NEAR(r.scene->shapes.at(0)->bsdf->eval(si, wo, wi).g, 0.5f * kInvPi * wi.z, 1e-6f);

  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="blendbsdf"><bsdf type="diffuse"/></bsdf></shape>)"),
               SceneError);
}

}  // namespace
}  // namespace tessera
