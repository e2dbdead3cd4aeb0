// BSDFs in importance transport (render/bsdf_adjoint.h): the adjoint that light subpaths use,
// eval with its arguments swapped, must equal pbrt-v4's importance-mode evaluation, which is the
// radiance-mode one times eta^2 on a refraction (the radiance scaling undone) and Veach's
// shading-normal correction. For every BSDF with a non-delta part, at a shading frame tilted
// from the geometry, in both hemispheres: this holds exactly when the BSDF is reciprocal (and a
// refraction obeys generalised reciprocity), which light tracing's agreement with the path
// tracer relies on.
#include "bsdf_test_util.h"
#include "tessera/render/bsdf_adjoint.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace tessera {
namespace {

using namespace tessera::test;

const std::vector<std::pair<std::string, std::string>> kBsdfs = {
    {"diffuse", R"(<bsdf type="diffuse"><rgb name="reflectance" value="0.6,0.5,0.4"/></bsdf>)"},
    {"roughdiffuse", R"(<bsdf type="roughdiffuse"><float name="alpha" value="0.5"/></bsdf>)"},
    {"plastic", R"(<bsdf type="plastic"/>)"},
    {"roughplastic", R"(<bsdf type="roughplastic"><float name="alpha" value="0.2"/></bsdf>)"},
    {"roughconductor", R"(<bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf>)"},
    {"roughconductor, anisotropic", R"(<bsdf type="roughconductor"><float name="alphaU" value="0.1"/>
        <float name="alphaV" value="0.4"/></bsdf>)"},
    {"phong", R"(<bsdf type="phong"><float name="exponent" value="20"/></bsdf>)"},
    {"coating", R"(<bsdf type="coating"><bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></bsdf>)"},
    {"roughcoating", R"(<bsdf type="roughcoating"><float name="alpha" value="0.2"/><bsdf type="diffuse"/></bsdf>)"},
    {"blendbsdf", R"(<bsdf type="blendbsdf"><float name="weight" value="0.3"/><bsdf type="diffuse"/>
        <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf></bsdf>)"},
    {"twosided", R"(<bsdf type="twosided"><bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></bsdf>)"},
    {"roughdielectric, ggx", R"(<bsdf type="roughdielectric"><float name="alpha" value="0.3"/>
        <string name="distribution" value="ggx"/><float name="intIOR" value="1.5"/><float name="extIOR" value="1"/></bsdf>)"},
    {"roughdielectric, beckmann", R"(<bsdf type="roughdielectric"><float name="alpha" value="0.2"/>
        <float name="intIOR" value="1.33"/><float name="extIOR" value="1"/></bsdf>)"},
};

// The BSDF of a sphere in a scene of its own (kept alive by the returned pointer).
std::shared_ptr<const Bsdf> load_bsdf(const std::string& xml) {
  auto scene = std::shared_ptr<Scene>(load_mitsuba06(R"(<shape type="sphere">)" + xml + "</shape>", "adjoint.xml").scene);
  const Bsdf* bsdf = scene->shapes.at(0)->bsdf;
  return bsdf ? std::shared_ptr<const Bsdf>(scene, bsdf) : nullptr;
}

// The interior of a dielectric (the side the geometric normal points away from).
float ior_of_side(const std::string& name, float cos_geometric) {
  if (name.rfind("roughdielectric", 0) != 0) return 1.f;
  const float inside = name.find("beckmann") != std::string::npos ? 1.33f : 1.5f;
  return cos_geometric < 0.f ? inside : 1.f;
}

TEST(BsdfAdjoint, SwappedEvaluationIsTheImportanceModeBsdf) {
  SurfaceInteraction si;
  si.ng = Vec3(0.f, 0.f, 1.f);
  si.shading = Frame(normalize(Vec3(0.25f, -0.15f, 1.f)));  // interpolated normals: the correction matters
  Pcg32 rng(9);
  for (const auto& [name, xml] : kBsdfs) {
    const auto bsdf = load_bsdf(xml);
    ASSERT_TRUE(bsdf) << name;
    int compared = 0;
    for (int i = 0; i < 4000; ++i) {
      const Vec3 prev = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
      const Vec3 next = square_to_uniform_sphere({rng.next_float(), rng.next_float()});
      if (!consistent_side(si, prev, si.to_local(prev)) || !consistent_side(si, next, si.to_local(next))) continue;
      // pbrt-v4: f(prev, next, Importance) = f(prev, next, Radiance) * etap^2 on a refraction, etap
      // the index on next's side over prev's; times the shading-normal correction.
      const float etap = ior_of_side(name, next.z) / ior_of_side(name, prev.z);
      const float correction = std::abs(dot(prev, si.shading.n)) * std::abs(next.z) /
                               (std::abs(prev.z) * std::abs(dot(next, si.shading.n)));
      const Rgb expected = bsdf->eval(si, si.to_local(prev), si.to_local(next)) * (etap * etap * correction);
      const Rgb adjoint = adjoint_eval(si, *bsdf, prev, next);
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(adjoint[c], expected[c], 2e-3f * std::abs(expected[c]) + 1e-6f)
            << name << ": prev " << prev.x << "," << prev.y << "," << prev.z << " next " << next.x << "," << next.y
            << "," << next.z;
      compared += expected.max_value() > 0.f;
    }
    EXPECT_GT(compared, 200) << name << ": the BSDF is not black";
  }
}

// A delta lobe's importance weight: a refraction through smooth glass carries its radiance
// weight times eta^2 (energy, not radiance, is what crosses); a reflection keeps it.
TEST(BsdfAdjoint, ADeltaRefractionUndoesTheRadianceScaling) {
  const auto glass = load_bsdf(R"(<bsdf type="dielectric"><float name="intIOR" value="1.5"/><float name="extIOR" value="1"/></bsdf>)");
  SurfaceInteraction si;
  si.ng = Vec3(0.f, 0.f, 1.f);
  si.shading = Frame(si.ng);
  const Vec3 wo = normalize(Vec3(0.3f, 0.1f, 1.f));
  for (float u : {0.01f, 0.99f}) {  // reflection, refraction
    BsdfSample bs;
    ASSERT_TRUE(glass->sample(si, wo, u, {0.5f, 0.5f}, bs));
    const Rgb w = adjoint_weight(si, bs, si.to_world(wo), si.to_world(bs.wi));
    const bool refracted = bs.wi.z < 0.f;
    const float fresnel_part = refracted ? bs.weight.g * bs.eta * bs.eta : bs.weight.g;
    EXPECT_NEAR(w.g, fresnel_part, 1e-5f);
    if (refracted) {
      EXPECT_NEAR(w.g, 1.f, 1e-4f) << "weight (1 - F) / (1 - F), energy kept";
    }
  }
}

}  // namespace
}  // namespace tessera
