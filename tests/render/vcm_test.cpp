// Vertex connection and merging (render/vcm.h): without merging it is bdpt to the bit; with it,
// it converges to the path tracer's image; without connections (photon mapping) to sppm's; the
// same bits for any thread count and tile size. Merging is consistent, not unbiased, so the
// comparisons use a small radius and allow for the estimators' noise (independent renders).
#include "image_agreement.h"
#include "independent_renders.h"
#include "scene_builders.h"
#include "tessera/render/vcm.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

namespace tessera {
namespace {

using namespace tessera::test;

// A point light above a glass ball on a diffuse floor, in a diffuse room: the floor under the
// ball is lit only through the glass (a caustic no camera path and no connection can find).
const char* kCausticScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="8"/></integrator>
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0,2.2,2.6" target="0,0.2,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.6"/></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><rotate x="1" angle="-90"/></transform><ref id="white"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/><translate z="-1.5"/></transform><ref id="white"/></shape>
  <shape type="sphere"><point name="center" x="0" y="0.4" z="0"/><float name="radius" value="0.4"/><bsdf type="dielectric"/></shape>
  <emitter type="point"><point name="position" x="0.3" y="2" z="0.2"/><rgb name="intensity" value="6"/></emitter>
</scene>)";

bool same_image(const Film& a, const Film& b) {
  const Image ia = a.to_image(), ib = b.to_image();
  return ia.width() == ib.width() && ia.height() == ib.height() &&
         std::memcmp(ia.data(), ib.data(), size_t(ia.width()) * size_t(ia.height()) * 3 * sizeof(float)) == 0;
}

TEST(Vcm, WithoutMergingIsBdptBitForBit) {
  const auto bdpt = load_as(kMixedScene, "bdpt");
  auto vcm = load_as(kMixedScene, "vcm");
  vcm->integrator.merge = false;
  const Film a = render(*bdpt, render_settings(9, 3)), b = render(*vcm, render_settings(9, 3));
  EXPECT_TRUE(same_bits(a, b)) << "the camera subpaths' sums";
  EXPECT_TRUE(same_image(a, b)) << "the image, light tracing's splats included";
}

// Metal of alpha 0.3 everywhere, the emitters too (smoother than merge_roughness 0.5), lit by a
// sphere and a quad.
const char* kGlossyScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="5"/></integrator>
  <sensor type="perspective"><float name="fov" value="55"/>
    <transform name="to_world"><lookat origin="0,1.2,4.5" target="0,0.6,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="24"/><integer name="height" value="18"/><rfilter type="box"/></film>
  </sensor>
  <bsdf type="roughconductor" id="metal"><float name="alpha" value="0.3"/></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform><ref id="metal"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><translate z="-2"/></transform><ref id="metal"/></shape>
  <shape type="sphere"><point name="center" x="0.4" y="0.45" z="0.4"/><float name="radius" value="0.45"/><ref id="metal"/></shape>
  <shape type="sphere"><point name="center" x="0.8" y="2.2" z="-0.5"/><float name="radius" value="0.25"/>
    <ref id="metal"/><emitter type="area"><rgb name="radiance" value="12,10,8"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/>
    <translate x="-0.8" y="2.5" z="0.2"/></transform><ref id="metal"/><emitter type="area"><rgb name="radiance" value="4,4,5"/></emitter></shape>
</scene>)";

// Where the rules leave no merge, every merge term is gone from every weight: bdpt's image, bit
// for bit (its pixel sums are taken in another order: vcm's program has a pass per iteration). Paths
// of at most two segments have only direct light (merge_direct false); a scene of metal smoother
// than merge_roughness has no vertex that merges.
TEST(Vcm, WhereNoVertexMergesItIsBdptBitForBit) {
  for (const int max_depth : {1, 2}) {
    auto bdpt = load_as(kMixedScene, "bdpt");
    auto vcm = load_as(kMixedScene, "vcm");
    for (Scene* s : {bdpt.get(), vcm.get()}) s->integrator.max_depth = max_depth;
    vcm->integrator.initial_radius = 0.3f;
    EXPECT_TRUE(same_image(render(*bdpt, render_settings(4, 3)), render(*vcm, render_settings(4, 3))))
        << "direct light only, max_depth " << max_depth;
  }
  const auto bdpt = load_as(kGlossyScene, "bdpt");
  auto vcm = load_as(kGlossyScene, "vcm");
  vcm->integrator.initial_radius = 0.3f;
  vcm->integrator.merge_roughness = 0.5f;
  const Film a = render(*bdpt, render_settings(4, 3)), b = render(*vcm, render_settings(4, 3));
  EXPECT_TRUE(same_image(a, b)) << "no surface rough enough to merge";
  vcm->integrator.merge_roughness = 0.2f;
  EXPECT_FALSE(same_image(a, render(*vcm, render_settings(4, 3)))) << "rough enough to merge: not bdpt";
}

// SmallVCM's merges (everywhere, direct light too), the defaults (no direct light), and only
// where the BSDF is rough (merge_roughness 0.5: the rough metal sphere, alpha 0.15, neither
// merges nor counts merges in its strategies' weights) all converge to the path tracer's image.
TEST(Vcm, ConvergesToPathOnTheMixedScene) {
  const Estimate path = estimate(*load_as(kMixedScene, "path"), 64, 16, 8, 100);
  struct Rules {
    float merge_roughness;
    bool merge_direct;
  };
  for (const Rules rules : {Rules{0.f, true}, Rules{0.1f, false}, Rules{0.5f, false}}) {
    auto vcm = load_as(kMixedScene, "vcm");
    vcm->integrator.initial_radius = 0.1f;
    vcm->integrator.merge_roughness = rules.merge_roughness;
    vcm->integrator.merge_direct = rules.merge_direct;
    const Estimate merged = estimate(*vcm, 16, 16, 8, 200);
    expect_agree(merged, path, 6.0,
                 "vcm vs path (mixed), merge_roughness " + std::to_string(rules.merge_roughness) + ", merge_direct " +
                     (rules.merge_direct ? "true" : "false"));
  }
}

// Photon mapping (no connections) and sppm converge to the same image, caustic included; at a
// fixed radius (alpha 1) they differ by their kernels' bias (photon mapping blurs direct light
// too), a few per cent, and their noise.
TEST(Vcm, WithoutConnectionsConvergesToSppmsImage) {
  auto ppm = load_as(kCausticScene, "vcm");
  ppm->integrator.connect = false;
  auto sppm = load_as(kCausticScene, "sppm");
  for (Scene* s : {ppm.get(), sppm.get()}) {
    s->integrator.initial_radius = 0.1f;
    s->integrator.alpha = 1.f;
    s->integrator.photon_count = 20000;
  }
  const Estimate a = estimate(*ppm, 64, 8, 6, 300), b = estimate(*sppm, 16, 8, 6, 400);
  for (size_t i = 0; i < a.blocks.size(); ++i)
    for (size_t c = 0; c < 3; ++c) {
      const double allowed = 4.0 * std::sqrt(a.se2[i][c] + b.se2[i][c]) + 0.05 * b.mean[i][c];
      EXPECT_LT(std::abs(a.mean[i][c] - b.mean[i][c]), allowed)
          << "block (" << a.blocks[i][0] << "," << a.blocks[i][1] << ") channel " << c << ": " << a.mean[i][c]
          << " vs sppm " << b.mean[i][c];
    }
  EXPECT_GT(b.mean[0][1], 0.05) << "the image is lit";
}

TEST(Vcm, SameBitsForAnyThreadCountAndTileSize) {
  auto vcm = load_as(kMixedScene, "vcm");
  RenderSettings a = render_settings(4, 11);
  a.threads = 1;
  a.tile_size = 32;
  RenderSettings b = a;
  b.threads = 2;
  b.tile_size = 5;
  const Film fa = render(*vcm, a), fb = render(*vcm, b);
  EXPECT_TRUE(same_bits(fa, fb));
  EXPECT_TRUE(same_image(fa, fb));
  EXPECT_EQ(fa.counters().nonfinite, 0u);
}

}  // namespace
}  // namespace tessera
