// Rough plastic: chi-square of sample() against pdf() over roughness, distribution and incidence;
// weights against eval/pdf; the numerically built coat tables; energy (white base <= 1, the white-furnace
// table of docs/microfacet-albedo.md, and the smooth plastic's albedo as alpha -> 0); loading from Mitsuba 0.6 XML.
#include "tessera/bsdf/roughplastic.h"

#include "tessera/bsdf/dielectric.h"
#include "tessera/bsdf/fresnel.h"
#include "tessera/core/frame.h"
#include "tessera/core/hash.h"
#include "tessera/scene/error.h"
#include "tessera/scene/load_context.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>

namespace tessera {
namespace {

std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }

const Vec3 kWo[] = {Vec3(0.f, 0.f, 1.f), normalize(Vec3(0.6f, -0.3f, 0.5f)), normalize(Vec3(-0.9f, 0.1f, 0.15f)),
                    normalize(Vec3(0.2f, 0.99f, 0.088f))};

// Monte Carlo albedo (mean sample weight) for a fixed wo, deterministic seed.
Rgb albedo(const Bsdf& bsdf, Vec3 wo, int n = 200000) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  SurfaceInteraction si;
  double r = 0, g = 0, b = 0;
  for (int i = 0; i < n; ++i) {
    BsdfSample bs;
    const float u1 = u(rng), u2 = u(rng), u3 = u(rng);
    if (!bsdf.sample(si, wo, u1, Vec2(u2, u3), bs)) continue;
    r += bs.weight.r, g += bs.weight.g, b += bs.weight.b;
  }
  return Rgb(float(r / n), float(g / n), float(b / n));
}

TEST(RoughPlastic, Chi2SampleMatchesPdf) {
  struct Case {
    MicrofacetType type;
    float alpha, eta;
  };
  const Case cases[] = {{MicrofacetType::Beckmann, 0.05f, 1.49f}, {MicrofacetType::Beckmann, 0.3f, 1.49f},
                        {MicrofacetType::Ggx, 0.1f, 1.8f},         {MicrofacetType::Ggx, 0.6f, 1.49f},
                        {MicrofacetType::Phong, 0.2f, 1.33f}};
  test::Chi2Options o;
  o.test_count = int(std::size(cases) * std::size(kWo));
  o.name = "roughplastic";
  o.sample_count = 200000;
  for (const Case& c : cases) {
    auto bsdf = make_roughplastic_bsdf(c.type, c.alpha, c.eta, constant(Rgb(0.5f)), constant(Rgb(1.f)), false);
    for (Vec3 wo : kWo) {
      test::Chi2Options oc = o;
      if (c.alpha < 0.1f || wo.z < 0.2f) {
        // Narrow lobes, or the reflected lobe squeezed against the horizon: finer bins.
        oc.cos_theta_bins = 200;
        oc.phi_bins = 400;
        oc.sample_count = 600000;
      }
      auto r = test::chi2_test(
          test::Chi2Sampler3([&](Vec2 u, float u1) -> test::Chi2Sample {
            SurfaceInteraction si;
            BsdfSample bs;
            if (!bsdf->sample(si, wo, u1, u, bs)) return {Vec3(), 0.f, false};
            return {bs.wi, bs.pdf, true};
          }),
          [&](Vec3 wi) {
            SurfaceInteraction si;
            return double(bsdf->pdf(si, wo, wi));
          },
          oc);
      EXPECT_TRUE(r.passed) << "type " << int(c.type) << " alpha " << c.alpha << " wo.z " << wo.z << "\n"
                            << r.message;
    }
  }
}

TEST(RoughPlastic, WeightIsEvalOverPdf) {
  auto bsdf = make_roughplastic_bsdf(MicrofacetType::Ggx, 0.25f, 1.5f, constant(Rgb(0.7f, 0.3f, 0.1f)),
                                     constant(Rgb(0.9f)), true);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  SurfaceInteraction si;
  int ok = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 wo = kWo[i % 4];
    BsdfSample bs;
    if (!bsdf->sample(si, wo, u(rng), Vec2(u(rng), u(rng)), bs)) continue;
    ++ok;
    EXPECT_FALSE(bs.delta);
    const float pdf = bsdf->pdf(si, wo, bs.wi);
    const Rgb f = bsdf->eval(si, wo, bs.wi);
    EXPECT_NEAR(bs.pdf, pdf, 1e-4f * pdf);
    EXPECT_NEAR(bs.weight.r, f.r / pdf, 1e-4f * f.r / pdf + 1e-7f);
    EXPECT_NEAR(bs.weight.b, f.b / pdf, 1e-4f * f.b / pdf + 1e-7f);
  }
  EXPECT_GT(ok, 1900);
  // Below the surface: nothing.
  BsdfSample bs;
  EXPECT_FALSE(bsdf->sample(si, Vec3(0.f, 0.f, -1.f), 0.5f, Vec2(0.5f, 0.5f), bs));
  EXPECT_EQ(bsdf->pdf(si, Vec3(0.f, 0.f, 1.f), Vec3(0.f, 0.f, -1.f)), 0.f);
}

TEST(RoughPlastic, CoatTransmittanceTendsToFresnel) {
  for (float eta : {1.33f, 1.49f, 2.0f}) {
    for (float c : {1.f, 0.7f, 0.4f}) {
      EXPECT_NEAR(rough_dielectric_transmittance(MicrofacetType::Beckmann, 1e-3f, eta, c),
                  1.f - fresnel_dielectric(c, eta), 2e-3f);
    }
    // Inside the coat, beyond the critical angle: total internal reflection.
    EXPECT_NEAR(rough_dielectric_transmittance(MicrofacetType::Ggx, 1e-3f, 1.f / eta, 0.2f), 0.f, 1e-3f);
  }
  // Rough: a fraction in (0, 1) that shrinks towards grazing incidence (masking).
  for (MicrofacetType t : {MicrofacetType::Beckmann, MicrofacetType::Ggx, MicrofacetType::Phong}) {
    float prev = 1.f;
    for (float c : {1.f, 0.5f, 0.2f, 0.05f}) {
      const float tr = rough_dielectric_transmittance(t, 0.5f, 1.5f, c);
      EXPECT_GT(tr, 0.f);
      EXPECT_LT(tr, prev) << c;
      prev = tr;
    }
  }
}

TEST(RoughPlastic, EnergyWhiteBase) {
  for (MicrofacetType type : {MicrofacetType::Beckmann, MicrofacetType::Ggx}) {
    for (float alpha : {0.05f, 0.2f, 0.6f}) {
      auto bsdf = make_roughplastic_bsdf(type, alpha, 1.49f, constant(Rgb(1.f)), constant(Rgb(1.f)), false);
      for (Vec3 wo : kWo) {
        const float a = albedo(*bsdf, wo).g;
        EXPECT_LE(a, 1.01f) << "alpha " << alpha << " wo.z " << wo.z;
        EXPECT_GT(a, 0.5f) << "alpha " << alpha << " wo.z " << wo.z;
      }
    }
  }
  // Nearly smooth: the smooth plastic's albedo (1 for a white base) away from grazing incidence.
  auto rough = make_roughplastic_bsdf(MicrofacetType::Beckmann, 0.01f, 1.49f, constant(Rgb(1.f)),
                                      constant(Rgb(1.f)), false);
  auto smooth = make_plastic_bsdf(1.49f, constant(Rgb(1.f)), constant(Rgb(1.f)), false);
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(albedo(*rough, kWo[i]).g, albedo(*smooth, kWo[i]).g, 1e-2f) << kWo[i].z;
}

// Replicated jittered-stratified estimate of the directional albedo (mean sample() weight): the
// 3D stratification on (u1, u2) buys the table's 3 decimals within the runtime budget, and the
// spread of independent replicates gives an honest standard error despite the stratification.
struct FurnaceEstimate {
  double mean, stderr_;
};

double stratified_weight_sum(const Bsdf& bsdf, Vec3 wo, int k, Pcg32& rng) {
  SurfaceInteraction si;
  double sum = 0;
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k; ++j) {
      for (int l = 0; l < k; ++l) {
        // Separate statements: argument evaluation order is unspecified, the seed's stream is not.
        const float j1 = rng.next_float(), j2 = rng.next_float(), j3 = rng.next_float();
        // (s + j) / k can round up to 1; sample() expects [0, 1).
        const auto stratum = [k](int s, float j) { return std::min((float(s) + j) / float(k), 0x1.fffffep-1f); };
        BsdfSample bs;
        if (bsdf.sample(si, wo, stratum(i, j1), Vec2(stratum(j, j2), stratum(l, j3)), bs)) sum += double(bs.weight.g);
      }
    }
  }
  return sum;
}

FurnaceEstimate furnace_albedo(const Bsdf& bsdf, Vec3 wo, int k, int replicates) {
  Pcg32 rng(7);
  const double n = double(k) * k * k;
  double sum = 0, sum2 = 0;
  for (int r = 0; r < replicates; ++r) {
    const double m = stratified_weight_sum(bsdf, wo, k, rng) / n;
    sum += m;
    sum2 += m * m;
  }
  const double mean = sum / replicates;
  const double var = std::max(0.0, (sum2 - replicates * mean * mean) / (replicates - 1));
  return {mean, std::sqrt(var / replicates)};
}

// The table of docs/microfacet-albedo.md ("Rough plastic: energy loss"), printed in markdown.
// With a white base and coat the model loses energy only through single scattering on the coat, so
// every cell must be <= 1 within noise; > 0 catches a sampler that silently fails.
TEST(RoughPlastic, WhiteFurnaceAlbedo) {
  const MicrofacetType types[] = {MicrofacetType::Beckmann, MicrofacetType::Ggx, MicrofacetType::Phong};
  const char* names[] = {"beckmann", "ggx", "phong"};
  const float alphas[] = {0.05f, 0.1f, 0.2f, 0.3f, 0.5f, 0.7f, 1.f};
  const float angles[] = {0.f, 45.f, 75.f, 85.f};
  const int k = 20, replicates = 16;
  double max_stderr = 0;
  std::string table = "| distribution | alpha | 0 deg | 45 deg | 75 deg | 85 deg |\n|---|---|---|---|---|---|\n";
  for (int ti = 0; ti < 3; ++ti) {
    for (float alpha : alphas) {
      auto linear = make_roughplastic_bsdf(types[ti], alpha, 1.5f, constant(Rgb(1.f)), constant(Rgb(1.f)), false);
      auto nonlinear = make_roughplastic_bsdf(types[ti], alpha, 1.5f, constant(Rgb(1.f)), constant(Rgb(1.f)), true);
      char buf[64];
      std::snprintf(buf, sizeof buf, "| %s | %.2f |", names[ti], alpha);
      table += buf;
      for (float deg : angles) {
        const float th = deg * kPi / 180.f;
        // Off-axis azimuth so that no cell relies on the sampler's behaviour along x or y.
        const Vec3 wo(std::sin(th) * std::cos(0.7f), std::sin(th) * std::sin(0.7f), std::cos(th));
        const std::string cell = std::string(names[ti]) + " alpha " + std::to_string(alpha) + " theta " +
                                 std::to_string(deg);
        const FurnaceEstimate e = furnace_albedo(*linear, wo, k, replicates);
        max_stderr = std::max(max_stderr, e.stderr_);
        std::snprintf(buf, sizeof buf, " %.3f |", e.mean);
        table += buf;
        double bound = 1.0 + 3.0 * e.stderr_;
        if (types[ti] == MicrofacetType::Phong && alpha >= 0.5f) {
          // Mitsuba's Phong borrows Beckmann's G1 at the equivalent alpha, which overshoots for
          // rough lobes (see the conductor table): up to ~1.02 here. Bounded so a change is noticed.
          bound += 0.05;
        }
        EXPECT_LE(e.mean, bound) << cell;
        EXPECT_GT(e.mean, 0.0) << cell;
        // A white base makes `nonlinear` a no-op (rho / (1 - Fdr) == rho / (1 - rho Fdr) at rho = 1),
        // so the table covers both; checked bit for bit on a smaller stratified set.
        Pcg32 rng_a(3), rng_b(3);
        EXPECT_EQ(stratified_weight_sum(*linear, wo, k / 2, rng_a), stratified_weight_sum(*nonlinear, wo, k / 2, rng_b))
            << cell;
      }
      table += "\n";
    }
  }
  std::printf("%s", table.c_str());
  std::printf("%d samples per cell, max standard error %.5f\n", k * k * k * replicates, max_stderr);
  // The doc quotes 3 decimals.
  EXPECT_LT(max_stderr, 5e-4);
}

LoadResult load_06(const std::string& body) {
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/rp.xml"), {});
}

TEST(RoughPlastic, LoadsMitsuba06Xml) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="roughplastic">
    <string name="distribution" value="ggx"/><float name="alpha" value="0.3"/>
    <string name="intIOR" value="bk7"/><float name="extIOR" value="1.0"/>
    <rgb name="diffuseReflectance" value="0.2, 0.4, 0.6"/><rgb name="specularReflectance" value="0.8"/>
    <boolean name="nonlinear" value="true"/></bsdf></shape>)");
  ASSERT_FALSE(r.scene->shapes.empty());
  const Bsdf& loaded = *r.scene->shapes.at(0)->bsdf;
  auto expected = make_roughplastic_bsdf(MicrofacetType::Ggx, 0.3f, 1.5046f, constant(Rgb(0.2f, 0.4f, 0.6f)),
                                         constant(Rgb(0.8f)), true);
  SurfaceInteraction si;
  const Vec3 wo = kWo[1], wi = normalize(Vec3(-0.4f, 0.2f, 0.7f));
  const Rgb a = loaded.eval(si, wo, wi), b = expected->eval(si, wo, wi);
  EXPECT_NEAR(a.r, b.r, 1e-6f);
  EXPECT_NEAR(a.b, b.b, 1e-6f);
  EXPECT_NEAR(loaded.pdf(si, wo, wi), expected->pdf(si, wo, wi), 1e-6f);

  // Defaults: beckmann, alpha 0.1, polypropylene / air, diffuse 0.5, specular 1, linear.
  r = load_06(R"(<shape type="sphere"><bsdf type="roughplastic"/></shape>)");
  auto defaults = make_roughplastic_bsdf(MicrofacetType::Beckmann, 0.1f, 1.49f / 1.000277f, constant(Rgb(0.5f)),
                                         constant(Rgb(1.f)), false);
  const Rgb c = r.scene->shapes.at(0)->bsdf->eval(si, wo, wi), d = defaults->eval(si, wo, wi);
  EXPECT_NEAR(c.g, d.g, 1e-6f);

  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughplastic">
    <string name="distribution" value="blinn"/></bsdf></shape>)"),
               SceneError);
  // The coat tables need a fixed roughness: a textured alpha is reported, not silently averaged.
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughplastic">
    <texture type="checkerboard" name="alpha"/></bsdf></shape>)"),
               UnsupportedError);
}

}  // namespace
}  // namespace tessera
