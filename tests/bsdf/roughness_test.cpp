// Bsdf::roughness, what vcm asks before it merges at a vertex: 1 for a diffuse lobe, a microfacet
// lobe's alpha, 0 for delta BSDFs, and wrappers answer for what they wrap.
#include "bsdf_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

namespace tessera {
namespace {

// The BSDF of a sphere in a scene of its own (kept alive by the returned pointer).
std::shared_ptr<const Bsdf> load_bsdf(const std::string& xml) {
  auto scene = std::shared_ptr<Scene>(test::load_mitsuba06(R"(<shape type="sphere">)" + xml + "</shape>", "rough.xml").scene);
  const Bsdf* bsdf = scene->shapes.at(0)->bsdf;
  return bsdf ? std::shared_ptr<const Bsdf>(scene, bsdf) : nullptr;
}

float roughness_of(const std::string& xml, bool from_back = false) {
  const auto bsdf = load_bsdf(xml);
  EXPECT_NE(bsdf, nullptr) << xml;
  if (!bsdf) return -1.f;
  SurfaceInteraction si;
  si.ng = Vec3(0.f, 0.f, 1.f);
  si.shading = Frame(si.ng);
  si.wo = Vec3(0.f, 0.f, from_back ? -1.f : 1.f);
  return bsdf->roughness(si);
}

TEST(BsdfRoughness, DiffuseIsOneMicrofacetsTheirAlphaDeltasZero) {
  EXPECT_EQ(roughness_of(R"(<bsdf type="diffuse"/>)"), 1.f);
  EXPECT_EQ(roughness_of(R"(<bsdf type="roughdiffuse"/>)"), 1.f);
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="roughconductor"><float name="alpha" value="0.05"/></bsdf>)"), 0.05f);
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="roughconductor"><float name="alphaU" value="0.3"/>
      <float name="alphaV" value="0.08"/></bsdf>)"), 0.08f) << "the smaller of an anisotropic pair";
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="roughdielectric"><float name="alpha" value="0.2"/></bsdf>)"), 0.2f);
  EXPECT_EQ(roughness_of(R"(<bsdf type="roughplastic"><float name="alpha" value="0.05"/></bsdf>)"), 1.f)
      << "its diffuse base";
  EXPECT_EQ(roughness_of(R"(<bsdf type="plastic"/>)"), 1.f);
  for (const char* delta : {R"(<bsdf type="conductor"/>)", R"(<bsdf type="dielectric"/>)", R"(<bsdf type="thindielectric"/>)"})
    EXPECT_EQ(roughness_of(delta), 0.f) << delta;
}

TEST(BsdfRoughness, PhongIsItsLobesWidth) {
  EXPECT_EQ(roughness_of(R"(<bsdf type="phong"><float name="exponent" value="100"/></bsdf>)"), 1.f)
      << "a diffuse part";
  EXPECT_NEAR(roughness_of(R"(<bsdf type="phong"><float name="exponent" value="98"/>
      <spectrum name="diffuseReflectance" value="0"/></bsdf>)"), std::sqrt(0.02f), 1e-6f);
}

TEST(BsdfRoughness, WrappersAnswerForWhatTheyWrap) {
  const std::string smooth = R"(<bsdf type="roughconductor"><float name="alpha" value="0.03"/></bsdf>)";
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="twosided">)" + smooth + "</bsdf>", true), 0.03f);
  EXPECT_EQ(roughness_of(R"(<bsdf type="twosided">)" + smooth + R"(<bsdf type="diffuse"/></bsdf>)", true), 1.f)
      << "the back's BSDF from the back";
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="twosided">)" + smooth + R"(<bsdf type="diffuse"/></bsdf>)"), 0.03f);
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="coating">)" + smooth + "</bsdf>"), 0.03f);
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="roughcoating"><float name="alpha" value="0.2"/>)" + smooth + "</bsdf>"),
                  0.2f) << "the rougher of coat and base";
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="mask"><float name="opacity" value="0.5"/>)" + smooth + "</bsdf>"), 0.03f);
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="bumpmap"><texture type="checkerboard"/>)" + smooth + "</bsdf>"), 0.03f);
  EXPECT_EQ(roughness_of(R"(<bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"/>)" + smooth +
                         "</bsdf>"),
            1.f)
      << "the rougher of the two";
  EXPECT_FLOAT_EQ(roughness_of(R"(<bsdf type="blendbsdf"><float name="weight" value="0"/>)" + smooth +
                               R"(<bsdf type="diffuse"/></bsdf>)"),
                  0.03f)
      << "a part of weight 0 is not there";
}

}  // namespace
}  // namespace tessera
