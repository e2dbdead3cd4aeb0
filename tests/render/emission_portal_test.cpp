// Where distant lights' light subpaths start (render/emission_portal.h): the portal samples lines
// with the density it reports, and its pilot finds a room's window. (That bdpt stays unbiased with
// it: Bdpt.ConvergesToPathThroughAWindowPane.)
#include "scene_builders.h"
#include "support/discrete_chi2.h"
#include "tessera/core/frame.h"
#include "tessera/core/hash.h"
#include "tessera/render/emission_portal.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace tessera {
namespace {

using namespace tessera::test;

float u01(uint64_t i, uint64_t dim) { return bits_to_unit_float(uint32_t(hash_values(i, dim, 0x9e3779b9ull) >> 32)); }

// Three boxes, two of them overlapping (lines through both count twice), inside a sphere of radius 2.
EmissionPortal three_boxes() {
  EmissionPortal p;
  p.set_scene_sphere(Vec3(0.f), 2.f);
  p.add_box({Vec3(-1.1f, -0.5f, -0.5f), Vec3(-0.9f, 0.5f, 0.5f)});
  p.add_box({Vec3(0.2f, 0.2f, 0.2f), Vec3(0.6f, 0.9f, 0.4f)});
  p.add_box({Vec3(0.5f, 0.5f, 0.3f), Vec3(0.8f, 0.8f, 0.8f)});
  return p;
}

// Lines along `dir` binned by where they cross the plane through the sphere's centre facing dir,
// on a kBins x kBins grid over [-2, 2]^2; each bin's probability is the pdf integrated over it.
TEST(EmissionPortal, SamplesLinesWithTheDensityItReports) {
  constexpr int kBins = 12, kSub = 64, kSamples = 100000;
  const EmissionPortal portal = three_boxes();
  for (const Vec3 dir : {normalize(Vec3(1.f, 0.3f, -0.2f)), normalize(Vec3(-0.2f, -1.f, 0.7f)), Vec3(0.f, 0.f, 1.f)}) {
    const Frame frame(dir);
    const float cell = 4.f / kBins;
    std::vector<double> probs(kBins * kBins, 0.0);
    double total = 0;
    for (int b = 0; b < kBins * kBins; ++b)
      for (int j = 0; j < kSub * kSub; ++j) {
        const float a = -2.f + cell * (float(b % kBins) + (float(j % kSub) + 0.5f) / kSub);
        const float c = -2.f + cell * (float(b / kBins) + (float(j / kSub) + 0.5f) / kSub);
        const double p = portal.pdf(frame.s * a + frame.t * c, dir) * double(cell * cell) / (kSub * kSub);
        probs[size_t(b)] += p;
        total += p;
      }
    EXPECT_NEAR(total, 1.0, 2e-3) << "the density integrates to one";
    std::vector<uint64_t> counts(probs.size(), 0);
    int consistent = 0;
    for (int i = 0; i < kSamples; ++i) {
      Vec3 p;
      float pdf = 0.f;
      ASSERT_TRUE(portal.sample(dir, Vec2(u01(uint64_t(i), 0), u01(uint64_t(i), 1)), p, pdf));
      EXPECT_LE(dot(p, dir), -2.f + 1e-4f) << "starts upstream of the sphere";
      const float a = dot(p, frame.s), c = dot(p, frame.t);
      const int bx = int((a + 2.f) / cell), by = int((c + 2.f) / cell);
      ASSERT_TRUE(bx >= 0 && bx < kBins && by >= 0 && by < kBins);
      ++counts[size_t(by * kBins + bx)];
      consistent += std::abs(portal.pdf(p, dir) - pdf) <= 1e-4f * pdf ? 1 : 0;
    }
    EXPECT_GE(consistent, kSamples * 999 / 1000) << "sample() and pdf() agree on the sampled lines";
    const DiscreteChi2Result r = discrete_chi2(counts, probs, 0, 0.0, 0.01, 3);
    EXPECT_TRUE(r.passed) << r.message;
  }
}

TEST(EmissionPortal, WithoutBoxesIsTheDiskOfTheSceneSphere) {
  EmissionPortal portal;
  portal.set_scene_sphere(Vec3(1.f, 2.f, 3.f), 2.f);
  const Vec3 dir = normalize(Vec3(0.3f, -1.f, 0.2f));
  EXPECT_FLOAT_EQ(portal.pdf(Vec3(1.f, 2.f, 3.f), dir), 1.f / (kPi * 4.f));
  EXPECT_EQ(portal.pdf(Vec3(1.f, 2.f, 3.f) + normalize(cross(dir, Vec3(1.f, 0.f, 0.f))) * 2.01f, dir), 0.f);
  Vec3 p;
  float pdf = 0.f;
  ASSERT_TRUE(portal.sample(dir, Vec2(0.3f, 0.7f), p, pdf));
  EXPECT_FLOAT_EQ(pdf, 1.f / (kPi * 4.f));
}

std::unique_ptr<Scene> load_bdpt(std::string xml) {
  LoadOptions o;
  o.integrator = "bdpt";
  return load_scene(parse_scene_string(xml, "portal_test.xml"), o).scene;
}

// The window scene's only opening is the pane in the wall x = -1, |y|, |z| <= 0.5.
TEST(EmissionPortal, FindsTheWindowOfARoom) {
  const auto scene = load_bdpt(kWindowScene);
  const EmissionPortal& portal = scene->emission_portal();
  ASSERT_TRUE(portal.active());
  EXPECT_GE(portal.escapes(), 100u);
  ASSERT_GT(portal.box_count(), 0);
  for (int i = 0; i < portal.box_count(); ++i) EXPECT_LT(portal.box(i).hi.x, -0.9f) << "box " << i << " is off the window";
  int covered = 0;
  for (float y = -0.35f; y <= 0.36f; y += 0.1f)
    for (float z = -0.35f; z <= 0.36f; z += 0.1f)
      for (int i = 0; i < portal.box_count(); ++i)
        if (portal.box(i).contains(Vec3(-1.f, y, z))) {
          ++covered;
          break;
        }
  EXPECT_EQ(covered, 64) << "the middle of the pane is covered";
}

TEST(EmissionPortal, AClosedRoomHasNoBoxesAndThePathTracerNone) {
  std::string closed = kWindowScene;
  const std::string pane = "<bsdf type=\"thindielectric\"/>";
  closed.replace(closed.find(pane), pane.size(), "<ref id=\"wall\"/>");
  const auto scene = load_bdpt(closed);
  EXPECT_TRUE(scene->emission_portal().active());
  EXPECT_EQ(scene->emission_portal().box_count(), 0);
  EXPECT_FALSE(window_scene()->emission_portal().active());
}

}  // namespace
}  // namespace tessera
