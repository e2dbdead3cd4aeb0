// Whether guiding pays (guiding/guide_gain.h): a path's reweighting predicts plain path tracing's
// second moment exactly in expectation, the sums are the same bits in any order, and a spatial
// tree steps aside once, at the deciding iteration, when the prediction is below the least gain.
#include "tessera/guiding/guide_gain.h"
#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/path_guide.h"

#include "tessera/core/hash.h"

#include <gtest/gtest.h>

#include <array>

namespace tessera {
namespace {

// Two vertices with four outcomes each, the BSDF's probabilities b and the mixture's p; the path
// had found `e0` before them and finds f[i] / (its pdf) after each. The expectation over the
// mixture's outcomes of plain_moment() must be the second moment of the path BSDF sampling draws.
TEST(GuideGain, APathsReweightingIsPlainSecondMomentInExpectation) {
  const std::array<double, 4> b = {0.4, 0.3, 0.2, 0.1}, p = {0.1, 0.2, 0.3, 0.4}, f = {0.05, 0.2, 0.7, 1.3};
  const double e0 = 0.3;
  double predicted = 0.0, plain = 0.0, guided = 0.0;
  for (size_t i = 0; i < 4; ++i)
    for (size_t j = 0; j < 4; ++j) {
      // Guided: each step adds f / p times the throughput so far (its weights b / p stay 1 here:
      // the contributions are what the path added).
      const double after_i = e0 + f[i] / p[i];
      const double after_j = after_i + f[j] / (p[i] * p[j]);
      PathGain g;
      g.scattered(float(e0), float(p[i]), float(b[i]));
      g.scattered(float(after_i), float(p[j]), float(b[j]));
      predicted += p[i] * p[j] * g.plain_moment(float(after_j));
      guided += p[i] * p[j] * PathGain::guided_moment(float(after_j));
      const double plain_estimate = e0 + f[i] / b[i] + f[j] / (b[i] * b[j]);
      plain += b[i] * b[j] * plain_estimate * plain_estimate;
    }
  EXPECT_NEAR(predicted, plain, 1e-4 * plain);
  EXPECT_LT(guided, plain) << "this mixture follows f better than the BSDF does";
}

TEST(GuideGain, APathWithoutGuidedVerticesPredictsItsOwnMoment) {
  const PathGain g;
  EXPECT_DOUBLE_EQ(g.plain_moment(2.5f), PathGain::guided_moment(2.5f));
  EXPECT_DOUBLE_EQ(PathGain::guided_moment(2.5f), 6.25);
}

TEST(GuideGain, SumsAreTheSameBitsInAnyOrder) {
  GuideGain forward, backward;
  std::array<std::array<float, 3>, 64> records;
  Pcg32 rng(7);
  for (auto& r : records) r = {rng.next_float() * 9.f, rng.next_float() * 3.f, rng.next_float()};
  for (const auto& r : records) forward.record(r[0], r[1], r[2]);
  for (size_t k = records.size(); k-- > 0;) backward.record(records[k][0], records[k][1], records[k][2]);
  EXPECT_EQ(forward, backward);
  EXPECT_GT(forward.ratio(), 1.0);
  EXPECT_EQ(GuideGain{}.ratio(), 0.0) << "nothing recorded predicts nothing";
}

Bounds3 unit_box() {
  Bounds3 b;
  b.extend(Vec3(0.f));
  b.extend(Vec3(1.f));
  return b;
}

// A tree that has split, whose next iteration records paths of predicted gain `ratio`.
SpatialTree tree_predicting(double ratio) {
  GuidingSettings s;
  s.spatial_threshold = 2;
  SpatialTree tree(unit_box());
  for (int k = 0; k < 8; ++k) tree.record(tree.leaf_of(Vec3(0.3f)), Vec3(0.f, 0.f, 1.f), 1.f, 0.5f);
  tree.end_iteration(4, s);
  for (int k = 0; k < 100; ++k) tree.record_gain(ratio, 1.0, 0.5f);
  return tree;
}

// The defaults (a least gain of 1.3, deciding at the first iteration of 8 spp) but for the paths,
// which here are 100 an iteration.
GuidingSettings deciding() {
  GuidingSettings s;
  s.gain_paths = 100;
  return s;
}

TEST(GuideGain, ATreeStepsAsideWhereTheDecidingIterationPredictsLittle) {
  const GuidingSettings s = deciding();
  SpatialTree little = tree_predicting(1.05), much = tree_predicting(2.0);
  ASSERT_GT(little.leaf_count(), 1u);
  little.end_iteration(8, s);
  much.end_iteration(8, s);
  EXPECT_TRUE(little.stepped_aside());
  EXPECT_EQ(little.leaf_count(), 1u) << "what stepped aside keeps no trees";
  EXPECT_NEAR(little.predicted_gain(), 1.05, 1e-3);
  EXPECT_FALSE(much.stepped_aside());
  EXPECT_GT(much.leaf_count(), 1u);
  EXPECT_NEAR(much.predicted_gain(), 2.0, 1e-3);
  // Decided once: a later iteration that predicts little does not step aside.
  for (int k = 0; k < 100; ++k) much.record_gain(1.0, 1.0, 0.5f);
  much.end_iteration(16, s);
  EXPECT_FALSE(much.stepped_aside());
  // Passes with it render as the unguided path tracer: no guide.
  EXPECT_FALSE(PathGuide::of(&little, nullptr, true, false, s).has_value());
  EXPECT_TRUE(PathGuide::of(&much, nullptr, true, false, s).has_value());
  // A stepped-aside tree stays as it is.
  little.end_iteration(16, s);
  EXPECT_TRUE(little.stepped_aside());
}

TEST(GuideGain, NoDecisionBeforeTheDecidingIterationWithoutAMinimumOrWithTooFewPaths) {
  SpatialTree early = tree_predicting(1.0), never = tree_predicting(1.0);
  early.end_iteration(4, deciding());
  EXPECT_FALSE(early.stepped_aside());
  EXPECT_EQ(early.predicted_gain(), 0.f) << "an iteration of 4 spp does not decide";
  GuidingSettings off = deciding();
  off.min_gain = 0.0;
  never.end_iteration(8, off);
  EXPECT_FALSE(never.stepped_aside());
  SpatialTree few = tree_predicting(1.0);
  GuidingSettings more = deciding();
  more.gain_paths = 101;
  few.end_iteration(8, more);
  EXPECT_FALSE(few.stepped_aside());
  EXPECT_EQ(few.predicted_gain(), 0.f) << "100 paths do not decide where 101 must";
}

}  // namespace
}  // namespace tessera
