// Smooth conductor: the delta lobe's choice and weight (Fresnel * specular reflectance), the named
// metal table, and loading conductor / roughconductor from Mitsuba 0.6 XML.
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/fresnel.h"
#include "tessera/scene/load_context.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

namespace tessera {
namespace {

std::shared_ptr<Texture> constant(Rgb c) { return std::make_shared<ConstantTexture>(c); }

LoadResult load_06(const std::string& body) {
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/metal.xml"), {});
}

const Bsdf& first_bsdf(const LoadResult& r) {
  EXPECT_FALSE(r.scene->shapes.empty());
  EXPECT_NE(r.scene->shapes.at(0)->bsdf, nullptr);
  return *r.scene->shapes.at(0)->bsdf;
}

Rgb delta_weight(const Bsdf& b, Vec3 wo) {
  SurfaceInteraction si;
  BsdfSample bs;
  EXPECT_TRUE(b.sample(si, wo, 0.3f, {0.2f, 0.9f}, bs));
  return bs.weight;
}

void expect_rgb_near(Rgb a, Rgb b, float tol, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << what << " channel " << c;
}

TEST(Conductor, DeltaSampleIsMirrorWithFresnelWeight) {
  ConductorIor au = *lookup_metal("Au");
  Rgb spec(0.9f, 0.8f, 0.7f);
  auto b = make_conductor_bsdf(au, constant(spec));
  EXPECT_TRUE(b->is_delta());
  SurfaceInteraction si;
  for (float deg : {0.f, 30.f, 60.f, 85.f, 89.5f}) {
    float th = deg * kPi / 180.f;
    Vec3 wo(std::sin(th) * 0.6f, std::sin(th) * 0.8f, std::cos(th));
    BsdfSample bs;
    // Whatever the random numbers, the single lobe is chosen with probability 1.
    for (float u1 : {0.f, 0.5f, 0.999f}) {
      ASSERT_TRUE(b->sample(si, wo, u1, {0.7f, 0.1f}, bs));
      EXPECT_TRUE(bs.delta);
      EXPECT_EQ(bs.pdf, 1.f);
      EXPECT_NEAR(bs.wi.x, -wo.x, 1e-7f);
      EXPECT_NEAR(bs.wi.y, -wo.y, 1e-7f);
      EXPECT_NEAR(bs.wi.z, wo.z, 1e-7f);
      expect_rgb_near(bs.weight, fresnel_conductor(wo.z, au.eta, au.k) * spec, 1e-6f, "deg " + std::to_string(deg));
    }
    EXPECT_TRUE(b->eval(si, wo, bs.wi).is_black());
    EXPECT_EQ(b->pdf(si, wo, bs.wi), 0.f);
  }
  BsdfSample bs;
  EXPECT_FALSE(b->sample(si, Vec3(0.f, 0.f, -1.f), 0.5f, {0.5f, 0.5f}, bs));
}

TEST(Conductor, NamedMetals) {
  auto reflectance = [](const char* name) {
    auto ior = lookup_metal(name);
    EXPECT_TRUE(ior.has_value()) << name;
    return ior ? fresnel_conductor(1.f, ior->eta, ior->k) : Rgb();
  };
  Rgb au = reflectance("Au"), cu = reflectance("Cu"), ag = reflectance("Ag"), al = reflectance("Al");
  EXPECT_GT(au.r, au.b + 0.3f);  // gold is yellow-red
  EXPECT_GT(cu.r, cu.b + 0.3f);  // copper too
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(ag[c], 0.9f) << "silver is bright and neutral";
    EXPECT_GT(al[c], 0.85f) << "aluminium too";
  }
  for (const char* n : {"a-C", "Ag", "Al", "AlAs", "AlSb", "Au", "Be", "Cr", "CsI", "Cu", "Cu2O", "CuO", "d-C",
                        "Hg", "HgTe", "Ir", "K", "Li", "MgO", "Mo", "Na_palik", "Nb", "Ni_palik", "Rh", "Se",
                        "SiC", "SnTe", "Ta", "Te", "ThF4", "TiC", "TiN", "TiO2", "VC", "V_palik", "VN", "W",
                        "none"}) {
    auto ior = lookup_metal(n);
    ASSERT_TRUE(ior.has_value()) << n;
    for (int c = 0; c < 3; ++c) {
      EXPECT_GE(ior->eta[c], 0.f) << n;
      EXPECT_GE(ior->k[c], 0.f) << n;
    }
    EXPECT_NE(known_metal_names().find(n), std::string::npos) << n;
  }
  // "none" is a perfect mirror at every angle.
  ConductorIor none = *lookup_metal("none");
  for (float c : {1.f, 0.5f, 0.1f, 0.01f}) expect_rgb_near(fresnel_conductor(c, none.eta, none.k), Rgb(1.f), 1e-6f, "none");
  EXPECT_FALSE(lookup_metal("Unobtainium").has_value());
  EXPECT_FALSE(lookup_metal("au").has_value());  // case-sensitive, as Mitsuba's file names
}

TEST(ConductorFactory, DefaultsMaterialEtaKAndExtEta) {
  // Default: copper in air.
  ConductorIor cu = *lookup_metal("Cu");
  Vec3 wo = normalize(Vec3(0.3f, 0.1f, 0.8f));
  auto r = load_06(R"(<shape type="sphere"><bsdf type="conductor"/></shape>)");
  expect_rgb_near(delta_weight(first_bsdf(r), wo), fresnel_conductor(wo.z, cu.eta / 1.000277f, cu.k / 1.000277f),
                  1e-6f, "default Cu");
  // Named material, 0.6 camelCase names, ext_eta as a number.
  r = load_06(R"(<shape type="sphere"><bsdf type="conductor">
    <string name="material" value="Au"/><float name="extEta" value="1.5"/>
    <rgb name="specularReflectance" value="0.5, 0.25, 1"/></bsdf></shape>)");
  ConductorIor au = *lookup_metal("Au");
  expect_rgb_near(delta_weight(first_bsdf(r), wo),
                  fresnel_conductor(wo.z, au.eta / 1.5f, au.k / 1.5f) * Rgb(0.5f, 0.25f, 1.f), 1e-6f, "Au");
  // eta / k override the material; ext_eta by name.
  r = load_06(R"(<shape type="sphere"><bsdf type="conductor">
    <rgb name="eta" value="0.2, 0.9, 1.1"/><spectrum name="k" value="3"/><string name="extEta" value="water"/>
    </bsdf></shape>)");
  expect_rgb_near(delta_weight(first_bsdf(r), wo),
                  fresnel_conductor(wo.z, Rgb(0.2f, 0.9f, 1.1f) / 1.333f, Rgb(3.f) / 1.333f), 1e-6f, "eta/k");
  // Perfect mirror.
  r = load_06(R"(<shape type="sphere"><bsdf type="conductor"><string name="material" value="none"/></bsdf></shape>)");
  expect_rgb_near(delta_weight(first_bsdf(r), wo), Rgb(1.f), 1e-6f, "none");
}

TEST(ConductorFactory, UnknownMaterialIsASceneErrorNamingTheLine) {
  try {
    load_06("<shape type=\"sphere\">\n<bsdf type=\"roughconductor\">\n"
            "<string name=\"material\" value=\"Mithril\"/></bsdf></shape>");
    FAIL() << "expected SceneError";
  } catch (const SceneError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("Mithril"), std::string::npos) << msg;
    EXPECT_NE(msg.find("metal.xml:4"), std::string::npos) << msg;
  }
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="roughconductor">
    <string name="distribution" value="blinn"/></bsdf></shape>)"),
               SceneError);
  EXPECT_THROW(load_06(R"(<shape type="sphere"><bsdf type="conductor">
    <string name="extEta" value="unobtainium"/></bsdf></shape>)"),
               SceneError);
}

// roughconductor from 0.6 XML: alphaU / alphaV, specularReflectance, extEta all read; the value
// matches a directly constructed BSDF.
TEST(ConductorFactory, RoughConductorParameters) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="roughconductor">
    <string name="distribution" value="ggx"/><float name="alphaU" value="0.1"/><float name="alphaV" value="0.4"/>
    <string name="material" value="Al"/><float name="extEta" value="1.2"/>
    <rgb name="specularReflectance" value="0.8"/></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  ConductorIor al = *lookup_metal("Al");
  ConductorIor ior{al.eta / 1.2f, al.k / 1.2f};
  auto direct = make_roughconductor_bsdf(MicrofacetType::Ggx, constant(Rgb(0.1f)), constant(Rgb(0.4f)), ior,
                                         constant(Rgb(0.8f)));
  SurfaceInteraction si;
  Vec3 wo = normalize(Vec3(0.3f, 0.1f, 0.8f)), wi = normalize(Vec3(-0.2f, 0.05f, 0.9f));
  expect_rgb_near(first_bsdf(r).eval(si, wo, wi), direct->eval(si, wo, wi), 1e-6f, "eval");
  EXPECT_NEAR(first_bsdf(r).pdf(si, wo, wi), direct->pdf(si, wo, wi), 1e-6f);
  EXPECT_FALSE(first_bsdf(r).is_delta());
  // Isotropic alpha with phong.
  r = load_06(R"(<shape type="sphere"><bsdf type="roughconductor">
    <string name="distribution" value="phong"/><float name="alpha" value="0.3"/></bsdf></shape>)");
  EXPECT_TRUE(r.unsupported.empty());
  auto phong = make_roughconductor_bsdf(MicrofacetType::Phong, constant(Rgb(0.3f)), nullptr, *lookup_metal("Cu"),
                                        constant(Rgb(1.f)));
  Rgb expected = phong->eval(si, wo, wi);
  // Default ext_eta is air: compare with a small tolerance for the 1.000277 scaling.
  expect_rgb_near(first_bsdf(r).eval(si, wo, wi), expected, 2e-3f * expected.max_value() + 1e-6f, "phong");
}

}  // namespace
}  // namespace tessera
