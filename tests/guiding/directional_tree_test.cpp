// The directional quadtree of path guiding (guiding/directional_tree.h): its samples follow its pdf
// (chi-square), the pdf integrates to 1, statistics are exact whatever the order of the records,
// and refinement splits where the energy is and nowhere deeper than the cap.
#include "tessera/guiding/directional_tree.h"

#include "support/chi2.h"
#include "tessera/core/hash.h"
#include "tessera/core/sampling.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <thread>
#include <vector>

namespace tessera {
namespace {

struct Record {
  Vec3 dir;
  float value, dither;
};

// Radiance from a bright lobe around `axis`, a dimmer one around -z and a faint floor, as a path
// tracer would record it: direction drawn uniformly, value = radiance / pdf.
std::vector<Record> lobe_records(size_t n, uint64_t seed) {
  Pcg32 rng(seed);
  const Vec3 axis = normalize(Vec3(0.3f, -0.5f, 0.8f));
  std::vector<Record> out;
  out.reserve(n);
  for (size_t k = 0; k < n; ++k) {
    const Vec3 d = square_to_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    const float radiance = 40.f * std::pow(std::max(0.f, dot(d, axis)), 30.f) +
                           3.f * std::pow(std::max(0.f, -d.z), 8.f) + 0.05f;
    out.push_back({d, radiance * 4.f * kPi, rng.next_float()});
  }
  return out;
}

DirectionalTree trained(int iterations, size_t per_iteration) {
  DirectionalTree tree;
  for (int it = 0; it < iterations; ++it) {
    for (const Record& r : lobe_records(per_iteration, 7 + it)) tree.record(r.dir, r.value, r.dither);
    tree.build();
    if (it + 1 < iterations) tree = tree.refined(0.01);
  }
  return tree;
}

test::Chi2Result tree_chi2(const DirectionalTree& tree, const test::Chi2Options& o) {
  return test::chi2_test([&](Vec2 u) {
    float pdf = 0.f;
    const Vec3 d = tree.sample(u, pdf);
    return test::Chi2Sample{d, pdf};
  }, [&](Vec3 w) { return double(tree.pdf(w)); }, o);
}

TEST(DirectionalTree, SquareMapIsTheInverseOfTheSphereMap) {
  Pcg32 rng(3);
  for (int k = 0; k < 10000; ++k) {
    const Vec2 u(rng.next_float(), rng.next_float());
    const Vec2 back = direction_to_square(square_to_uniform_sphere(u));
    EXPECT_NEAR(back.x, u.x, 2e-6f);
    // (phi wraps around at y = 0 and 1; near the poles it is ill-defined)
    if (u.x > 1e-3f && u.x < 1.f - 1e-3f) {
      EXPECT_NEAR(std::fmod(back.y - u.y + 1.5f, 1.f), 0.5f, 2e-5f) << u.x;
    }
  }
}

TEST(DirectionalTree, MapsTheAzimuthAsAtan2Does) {
  // The polynomial arc tangent: within a few float roundings of double atan2 in every octant,
  // also on the axes and diagonals where its mirroring changes.
  Pcg32 rng(11);
  std::vector<Vec3> dirs;
  for (int k = 0; k < 100000; ++k) dirs.push_back(square_to_uniform_sphere(Vec2(rng.next_float(), rng.next_float())));
  for (float x : {-1.f, -0.6f, 0.f, 0.6f, 1.f})
    for (float y : {-1.f, -0.6f, 0.f, 0.6f, 1.f})
      if (x != 0.f || y != 0.f) dirs.push_back(normalize(Vec3(x, y, 0.25f)));
  double worst = 0.0;
  for (const Vec3& d : dirs) {
    double phi = std::atan2(double(d.y), double(d.x));
    if (phi < 0.0) phi += 2.0 * 3.14159265358979323846;
    const double y = direction_to_square(d).y, expected = std::min(phi / (2.0 * 3.14159265358979323846), 1.0 - 0x1p-24);
    worst = std::max(worst, std::min(std::abs(y - expected), 1.0 - std::abs(y - expected)));  // (y wraps at 0 and 1)
  }
  EXPECT_LT(worst, 2e-7);
}

TEST(DirectionalTree, TheBoxFilterSharesARecordByTheAreaItCovers) {
  // Cells of side 1/4: every root quadrant (a quarter of the energy, above 0.2) is split once.
  DirectionalTree uniform;
  for (int i = 0; i < 4; ++i) uniform.record_at(Vec2(0.25f + 0.5f * float(i & 1), 0.25f + 0.5f * float(i >> 1)), 1.f, 0.f);
  uniform.build();
  DirectionalTree tree = uniform.refined(0.2);
  ASSERT_EQ(tree.node_count(), 5u);
  // A box of side 1/4 about (0.3, 0.3) covers [0.175, 0.425)^2: 0.075 and 0.175 of the cells on
  // either side of 0.25 along each axis.
  tree.record_box(Vec2(0.3f, 0.3f), 16.f, 0.5f);
  tree.build();
  EXPECT_NEAR(DirectionalTree::from_fixed_point(double(tree.total())), 16.0, 1e-4);
  const double lo = 0.075, hi = 0.175;
  EXPECT_NEAR(tree.pdf_at(Vec2(0.1f, 0.1f)) / tree.pdf_at(Vec2(0.4f, 0.4f)), lo * lo / (hi * hi), 1e-4);
  EXPECT_NEAR(tree.pdf_at(Vec2(0.4f, 0.1f)) / tree.pdf_at(Vec2(0.4f, 0.4f)), lo / hi, 1e-4);
  EXPECT_EQ(tree.pdf_at(Vec2(0.6f, 0.3f)), 0.f);
  // Beside the square's edge the part outside is dropped (as Müller's code does).
  DirectionalTree edge = uniform.refined(0.2);
  edge.record_box(Vec2(0.05f, 0.6f), 16.f, 0.5f);
  edge.build();
  EXPECT_NEAR(DirectionalTree::from_fixed_point(double(edge.total())), 16.0 * (0.05 + 0.125) / 0.25, 1e-4);
}

TEST(DirectionalTree, AnEmptyTreeIsUniform) {
  DirectionalTree tree;
  tree.build();
  EXPECT_FLOAT_EQ(tree.pdf(Vec3(0.f, 0.f, 1.f)), 0.25f * kInvPi);
  test::Chi2Options o;
  o.name = "empty directional tree";
  o.sample_count = 200000;
  const test::Chi2Result r = tree_chi2(tree, o);
  EXPECT_TRUE(r.passed) << r.message;
}

TEST(DirectionalTree, SamplesFollowThePdfOfATrainedTree) {
  const DirectionalTree tree = trained(3, 200000);
  EXPECT_GT(tree.depth(), 4) << "the bright lobe should be cut finely";
  test::Chi2Options o;
  o.name = "trained directional tree";
  // Bins on powers of two, as the tree's cells are (its coarse cell edges fall on bin edges).
  o.cos_theta_bins = 128;
  o.phi_bins = 256;
  o.integration_resolution = 16;
  o.sample_count = 2000000;
  const test::Chi2Result r = tree_chi2(tree, o);
  EXPECT_TRUE(r.passed) << r.message;
  EXPECT_NEAR(r.pdf_integral, 1.0, 1e-2);
}

// A guided sample takes the density sample() returns for the mixture, without descending again.
TEST(DirectionalTree, TheSampledDensityIsThePdfAtTheDrawnPointBitForBit) {
  const DirectionalTree tree = trained(3, 200000);
  Pcg32 rng(5);
  for (int k = 0; k < 100000; ++k) {
    float pdf = 0.f;
    Vec2 square;
    const Vec3 d = tree.sample(Vec2(rng.next_float(), rng.next_float()), pdf, &square);
    ASSERT_EQ(pdf, tree.pdf_at(square)) << k;
    ASSERT_NEAR(length(d - square_to_uniform_sphere(square)), 0.f, 1e-6f);
  }
}

TEST(DirectionalTree, TheGuidedPdfFollowsTheRecordedEnergy) {
  const DirectionalTree tree = trained(3, 200000);
  const Vec3 axis = normalize(Vec3(0.3f, -0.5f, 0.8f));
  // Most of the energy is in the bright lobe: its pdf far above uniform, the faint floor below.
  EXPECT_GT(tree.pdf(axis), 20.f * 0.25f * kInvPi);
  EXPECT_LT(tree.pdf(normalize(Vec3(-0.7f, 0.7f, 0.1f))), 0.5f * 0.25f * kInvPi);
  EXPECT_GT(tree.pdf(normalize(Vec3(-0.7f, 0.7f, 0.1f))), 0.f) << "the floor still has energy";
}

TEST(DirectionalTree, StatisticsAreExactInAnyOrderAndAcrossThreads) {
  DirectionalTree structure = trained(2, 50000).refined(0.01);
  const std::vector<Record> records = lobe_records(100000, 99);
  DirectionalTree forward = structure, backward = structure, threaded = structure, half_a = structure,
                  half_b = structure;
  for (const Record& r : records) forward.record(r.dir, r.value, r.dither);
  for (auto it = records.rbegin(); it != records.rend(); ++it) backward.record(it->dir, it->value, it->dither);
  {
    std::vector<std::thread> threads;
    for (size_t t = 0; t < 4; ++t)
      threads.emplace_back([&, t] {
        for (size_t k = t; k < records.size(); k += 4) threaded.record(records[k].dir, records[k].value, records[k].dither);
      });
    for (std::thread& t : threads) t.join();
  }
  for (size_t k = 0; k < records.size(); ++k)
    (k % 3 ? half_a : half_b).record(records[k].dir, records[k].value, records[k].dither);
  half_a.merge(half_b);
  EXPECT_TRUE(forward == backward);
  EXPECT_TRUE(forward == threaded);
  EXPECT_TRUE(forward == half_a) << "two workers' trees merged are the tree of all records";
  forward.build();
  EXPECT_GT(forward.total(), 0u);
}

TEST(DirectionalTree, RoundingOfRecordsIsUnbiased) {
  // A value of a third of the fixed-point unit: rounded down two times in three on average.
  DirectionalTree tree;
  Pcg32 rng(5);
  const float unit = 1.f / float(uint64_t(1) << DirectionalTree::kScaleBits);
  const int n = 300000;
  for (int k = 0; k < n; ++k) tree.record(Vec3(0.f, 0.f, 1.f), unit / 3.f, rng.next_float());
  tree.build();
  const double expected = n / 3.0, sigma = std::sqrt(n * (1.0 / 3.0) * (2.0 / 3.0));
  EXPECT_NEAR(double(tree.total()), expected, 4.0 * sigma);
}

TEST(DirectionalTree, RefinementSplitsWhereTheEnergyIsUpToTheCap) {
  DirectionalTree tree;
  // All energy in one direction: split to the cap around it, and nowhere else.
  for (int k = 0; k < 1000; ++k) tree.record(normalize(Vec3(0.2f, 0.1f, 0.9f)), 1.f, 0.5f);
  tree.build();
  for (int it = 0; it < 25; ++it) {
    tree = tree.refined(0.01);
    for (int k = 0; k < 1000; ++k) tree.record(normalize(Vec3(0.2f, 0.1f, 0.9f)), 1.f, 0.5f);
    tree.build();
  }
  EXPECT_EQ(tree.depth(), DirectionalTree::kMaxDepth);
  EXPECT_EQ(tree.node_count(), size_t(DirectionalTree::kMaxDepth)) << "one chain of nodes";
  // Bad values are ignored, and an empty tree refines to one node.
  DirectionalTree empty;
  empty.record(Vec3(0.f, 0.f, 1.f), std::numeric_limits<float>::quiet_NaN(), 0.f);
  empty.record(Vec3(0.f, 0.f, 1.f), -1.f, 0.f);
  empty.build();
  EXPECT_EQ(empty.total(), 0u);
  EXPECT_EQ(empty.refined(0.01).node_count(), 1u);
}

TEST(DirectionalTree, EvenEnergyIsSplitUntilEachQuadrantIsBelowTheThreshold) {
  DirectionalTree tree;
  Pcg32 rng(11);
  for (int k = 0; k < 400000; ++k) {
    const Vec3 d = square_to_uniform_sphere(Vec2(rng.next_float(), rng.next_float()));
    tree.record(d, 1.f, rng.next_float());
  }
  tree.build();
  // Shares of 1/4, 1/16, 1/64 (> 0.01) are split; 1/256 is not: three levels below the root.
  const DirectionalTree next = tree.refined(0.01);
  EXPECT_EQ(next.depth(), 4);
  EXPECT_EQ(next.node_count(), size_t(1 + 4 + 16 + 64));
}

TEST(DirectionalTree, ARefinedTreeCanKeepTheEnergyLearnedSoFar) {
  const DirectionalTree tree = trained(2, 50000);
  DirectionalTree kept = tree.refined(0.01, /*keep_sums=*/true);
  DirectionalTree fresh = tree.refined(0.01);
  ASSERT_GT(kept.node_count(), 1u);
  kept.build();
  fresh.build();
  EXPECT_EQ(fresh.total(), 0u);
  // The same energy in finer cells: a leaf split into quarters loses at most 3 units of rounding.
  EXPECT_LE(kept.total(), tree.total());
  EXPECT_GE(kept.total() + 3 * kept.node_count(), tree.total());
  // Where the energy is, the density is what it was.
  const Vec3 lobe = normalize(Vec3(0.3f, -0.5f, 0.8f));
  EXPECT_NEAR(kept.pdf(lobe), tree.pdf(lobe), 1e-3 * tree.pdf(lobe));
  // Later records add to it, in the refined structure.
  for (const Record& r : lobe_records(1000, 99)) kept.record(r.dir, r.value, r.dither);
  const uint64_t before = kept.total();
  kept.build();
  EXPECT_GT(kept.total(), before);
}

}  // namespace
}  // namespace tessera
