// Loading dielectric, thindielectric and plastic from Mitsuba 0.6 XML (camelCase names), the named
// IOR table, and the error for an unknown IOR name.
#include "tessera/bsdf/dielectric.h"
#include "tessera/bsdf/ior.h"
#include "tessera/bsdf/fresnel.h"
#include "tessera/scene/load_context.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

LoadResult load_06(const std::string& body) {
  return load_scene(parse_scene_string("<scene version=\"0.6.0\">\n" + body + "\n</scene>\n", "mem/glass.xml"), {});
}

const Bsdf& first_bsdf(const LoadResult& r) {
  EXPECT_FALSE(r.scene->shapes.empty());
  EXPECT_NE(r.scene->shapes.at(0)->bsdf, nullptr);
  return *r.scene->shapes.at(0)->bsdf;
}

// Weight of the refracted sample at normal incidence from outside: (1 / eta)^2.
float refraction_weight(const Bsdf& b) {
  SurfaceInteraction si;
  BsdfSample bs;
  EXPECT_TRUE(b.sample(si, Vec3(0.f, 0.f, 1.f), 0.999999f, {}, bs));
  EXPECT_LT(bs.wi.z, 0.f);
  return bs.weight.g;
}

TEST(IorTable, NamesAndValues) {
  EXPECT_EQ(lookup_ior("bk7"), 1.5046f);
  EXPECT_EQ(lookup_ior("BK7"), 1.5046f);
  EXPECT_EQ(lookup_ior("air"), 1.000277f);
  EXPECT_EQ(lookup_ior("polypropylene"), 1.49f);
  EXPECT_EQ(lookup_ior("water ice"), 1.31f);
  EXPECT_EQ(lookup_ior("diamond"), 2.419f);
  EXPECT_EQ(lookup_ior("vacuum"), 1.f);
  EXPECT_FALSE(lookup_ior("unobtainium").has_value());
  const std::string names = known_ior_names();
  for (const char* n : {"vacuum", "helium", "hydrogen", "air", "carbon dioxide", "water", "acetone", "ethanol",
                        "carbon tetrachloride", "glycerol", "benzene", "silicone oil", "bromine", "water ice",
                        "fused quartz", "pyrex", "acrylic glass", "polypropylene", "bk7", "sodium chloride",
                        "amber", "pet", "diamond"}) {
    EXPECT_NE(names.find(n), std::string::npos) << n;
    EXPECT_TRUE(lookup_ior(n).has_value()) << n;
  }
}

TEST(SmoothFactories, DielectricDefaultsNamesAndNumbers) {
  // Defaults: bk7 inside, air outside.
  auto r = load_06(R"(<shape type="sphere"><bsdf type="dielectric"/></shape>)");
  const float eta_default = 1.5046f / 1.000277f;
  EXPECT_NEAR(refraction_weight(first_bsdf(r)), 1.f / (eta_default * eta_default), 1e-6f);
  // Names (any case) and numbers, camelCase 0.6 parameter names.
  r = load_06(R"(<shape type="sphere"><bsdf type="dielectric">
    <string name="intIOR" value="Water"/><string name="extIOR" value="vacuum"/>
    <spectrum name="specularTransmittance" value="0.5"/><rgb name="specularReflectance" value="0.25"/>
  </bsdf></shape>)");
  EXPECT_NEAR(refraction_weight(first_bsdf(r)), 0.5f / (1.333f * 1.333f), 1e-6f);
  SurfaceInteraction si;
  BsdfSample bs;
  ASSERT_TRUE(first_bsdf(r).sample(si, Vec3(0.f, 0.f, 1.f), 0.f, {}, bs));
  EXPECT_EQ(bs.weight, Rgb(0.25f));
  r = load_06(R"(<shape type="sphere"><bsdf type="dielectric">
    <float name="intIOR" value="1.5"/><float name="extIOR" value="1"/></bsdf></shape>)");
  EXPECT_NEAR(refraction_weight(first_bsdf(r)), 1.f / 2.25f, 1e-6f);
}

TEST(SmoothFactories, ThinDielectric) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="thindielectric">
    <float name="intIOR" value="1.5"/><float name="extIOR" value="1"/></bsdf></shape>)");
  const Bsdf& b = first_bsdf(r);
  EXPECT_TRUE(b.is_delta());
  SurfaceInteraction si;
  BsdfSample bs;
  ASSERT_TRUE(b.sample(si, Vec3(0.f, 0.f, 1.f), 0.f, {}, bs));
  const float r1 = 0.04f;  // ((1.5 - 1) / 2.5)^2
  EXPECT_NEAR(bs.pdf, r1 + (1 - r1) * (1 - r1) * r1 / (1 - r1 * r1), 1e-6f);
}

TEST(SmoothFactories, Plastic) {
  auto r = load_06(R"(<shape type="sphere"><bsdf type="plastic">
    <float name="intIOR" value="1.5"/><float name="extIOR" value="1"/>
    <rgb name="diffuseReflectance" value="0.2 0.4 0.6"/><spectrum name="specularReflectance" value="1"/>
    <boolean name="nonlinear" value="true"/></bsdf></shape>)");
  const Bsdf& b = first_bsdf(r);
  EXPECT_FALSE(b.is_delta());
  SurfaceInteraction si;
  Vec3 w(0.f, 0.f, 1.f);
  Rgb f = b.eval(si, w, w);
  const float fdr = fresnel_diffuse_reflectance(1.f / 1.5f), k = kInvPi / 2.25f * 0.96f * 0.96f;
  EXPECT_NEAR(f.r, 0.2f / (1 - 0.2f * fdr) * k, 1e-6f);
  EXPECT_NEAR(f.b, 0.6f / (1 - 0.6f * fdr) * k, 1e-6f);
  // Default int_ior is polypropylene (1.49).
  r = load_06(R"(<shape type="sphere"><bsdf type="plastic"/></shape>)");
  const float eta = 1.49f / 1.000277f, f0 = fresnel_dielectric(1.f, eta);
  EXPECT_NEAR(first_bsdf(r).eval(si, w, w).g,
              0.5f / (1 - fresnel_diffuse_reflectance(1.f / eta)) * kInvPi / (eta * eta) * (1 - f0) * (1 - f0), 1e-6f);
}

TEST(SmoothFactories, UnknownIorNameIsASceneErrorWithLocation) {
  try {
    load_06(R"(<shape type="sphere"><bsdf type="dielectric">
    <string name="intIOR" value="unobtainium"/></bsdf></shape>)");
    FAIL() << "expected a SceneError";
  } catch (const SceneError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("mem/glass.xml:3"), std::string::npos) << msg;
    EXPECT_NE(msg.find("unobtainium"), std::string::npos) << msg;
    EXPECT_NE(msg.find("bk7"), std::string::npos) << msg;
    EXPECT_NE(msg.find("polypropylene"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace tessera
