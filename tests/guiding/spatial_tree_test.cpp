// The spatial tree of path guiding (guiding/spatial_tree.h): splits decided by sample counts and
// the iteration, within the memory cap, the same bits for any order of records, and every point
// (also outside the bounds, or NaN) finds a leaf.
#include "tessera/guiding/spatial_tree.h"

#include "tessera/render/path_guide.h"
#include "tessera/render/sampler.h"

#include "tessera/core/hash.h"
#include "tessera/core/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <thread>
#include <vector>

namespace tessera {
namespace {

Bounds3 unit_box() {
  Bounds3 b;
  b.extend(Vec3(0.f));
  b.extend(Vec3(1.f));
  return b;
}

void record_at(SpatialTree& tree, Vec3 p, int n, uint64_t seed) {
  Pcg32 rng(seed);
  const uint32_t leaf = tree.leaf_of(p);
  for (int k = 0; k < n; ++k)
    tree.record(leaf, square_to_uniform_sphere(Vec2(rng.next_float(), rng.next_float())), rng.next_float() * 10.f,
                rng.next_float());
}

TEST(SpatialTree, ALeafIsSplitWhileItsHalvesStillHaveTooManySamples) {
  GuidingSettings s;
  s.spatial_threshold = 400;
  SpatialTree first(unit_box());
  record_at(first, Vec3(0.1f), 1000, 1);
  first.end_iteration(4, s);  // c·sqrt(4/4) = 400: 1000 > 400, halves of 500 > 400, quarters of 250 are not
  EXPECT_EQ(first.leaf_count(), 4u);
  EXPECT_EQ(first.node_count(), 7u);
  SpatialTree later(unit_box());
  record_at(later, Vec3(0.1f), 1000, 1);
  later.end_iteration(16, s);  // the threshold grows with sqrt(spp / 4): 800
  EXPECT_EQ(later.leaf_count(), 2u);
  // The one cut is along x at the middle.
  EXPECT_NE(later.leaf_of(Vec3(0.2f, 0.2f, 0.2f)), later.leaf_of(Vec3(0.7f, 0.2f, 0.2f)));
  EXPECT_EQ(later.leaf_of(Vec3(0.2f, 0.2f, 0.2f)), later.leaf_of(Vec3(0.2f, 0.9f, 0.9f)));
}

TEST(SpatialTree, PointsFindTheLeafOfTheirRegion) {
  GuidingSettings s;
  s.spatial_threshold = 100;
  SpatialTree tree(unit_box());
  record_at(tree, Vec3(0.05f), 2000, 2);
  tree.end_iteration(4, s);
  ASSERT_GT(tree.leaf_count(), 4u);
  // The first cut is x at 0.5, then y, then z; points on one side of every cut share a leaf.
  EXPECT_NE(tree.leaf_of(Vec3(0.2f, 0.2f, 0.2f)), tree.leaf_of(Vec3(0.7f, 0.2f, 0.2f)));
  EXPECT_NE(tree.leaf_of(Vec3(0.2f, 0.2f, 0.2f)), tree.leaf_of(Vec3(0.2f, 0.7f, 0.2f)));
  EXPECT_EQ(tree.leaf_of(Vec3(0.01f, 0.01f, 0.01f)), tree.leaf_of(Vec3(0.02f, 0.02f, 0.02f)));
  // Outside the bounds: the nearest region; NaN: some leaf, never out of range.
  EXPECT_EQ(tree.leaf_of(Vec3(-5.f, -5.f, -5.f)), tree.leaf_of(Vec3(0.f)));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_LT(tree.leaf_of(Vec3(nan, 0.f, 0.f)), tree.leaf_count());
  EXPECT_LT(tree.leaf_of(Vec3(std::numeric_limits<float>::infinity())), tree.leaf_count());
}

TEST(SpatialTree, LeavesKnowTheSizeOfTheirRegion) {
  GuidingSettings s;
  s.spatial_threshold = 100;
  SpatialTree tree(unit_box());
  record_at(tree, Vec3(0.05f), 2000, 2);
  record_at(tree, Vec3(0.8f, 0.3f, 0.6f), 700, 3);
  tree.end_iteration(4, s);
  ASSERT_GT(tree.leaf_count(), 8u);
  Pcg32 rng(4);
  for (int k = 0; k < 200; ++k) {
    const Vec3 p(rng.next_float(), rng.next_float(), rng.next_float());
    Vec3 e;
    const uint32_t leaf = tree.leaf_of(p, &e);
    // The region is the cell of a grid of that size: its inside is the leaf, just past it is not.
    const Vec3 lo(std::floor(p.x / e.x) * e.x, std::floor(p.y / e.y) * e.y, std::floor(p.z / e.z) * e.z);
    EXPECT_EQ(tree.leaf_of(lo + e * 0.01f), leaf);
    EXPECT_EQ(tree.leaf_of(lo + e * 0.99f), leaf);
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 past = lo + e * 0.5f;
      (&past.x)[axis] = (&lo.x)[axis] + 1.01f * (&e.x)[axis];
      if ((&past.x)[axis] < 1.f) EXPECT_NE(tree.leaf_of(past), leaf) << "axis " << axis;
    }
  }
}

TEST(SpatialTree, TheStochasticFilterRecordsIntoTheNeighboursOfALeaf) {
  GuidingSettings s;
  s.spatial_threshold = 400;
  SpatialTree tree(unit_box());
  record_at(tree, Vec3(0.1f), 1000, 1);
  tree.end_iteration(16, s);  // two leaves: x below and above 0.5
  ASSERT_EQ(tree.leaf_count(), 2u);
  const Vec3 p(0.45f, 0.5f, 0.5f);
  Vec3 extent;
  const uint32_t leaf = tree.leaf_of(p, &extent), other = tree.leaf_of(Vec3(0.9f, 0.5f, 0.5f));
  // A vertex 0.05 from the cut, in a leaf 0.5 wide: its box reaches 0.2 past the cut, 40% of it.
  const auto radiance_after = [&](SpatialFilter filter) {
    SpatialTree records = tree;
    const PathGuide guide{&tree, &records, false, true, GuideRoulette::Throughput, filter, DirectionalFilter::Nearest};
    Sampler sampler(SamplerType::Sobol, 1);
    for (uint32_t i = 0; i < 1000; ++i) {
      sampler.start_pixel_sample(Vec2i(3, 4), i);
      GuideRecords r;
      r.add(p, extent, leaf, Vec3(0.f, 0.f, 1.f), 1.f, 1.f, std::nullopt, Rgb(1.f), Rgb(0.f));
      r.commit(guide, Rgb(1.f), sampler);
    }
    records.end_iteration(16, s);
    return std::pair(records.radiance(leaf), records.radiance(other));
  };
  const auto nearest = radiance_after(SpatialFilter::Nearest);
  EXPECT_GT(nearest.first, 0.f);
  EXPECT_EQ(nearest.second, 0.f);
  const auto stochastic = radiance_after(SpatialFilter::Stochastic);
  EXPECT_GT(stochastic.first, 0.f);
  EXPECT_GT(stochastic.second, 0.f);
}

TEST(SpatialTree, TheSameRecordsInAnyOrderGiveTheSameTree) {
  GuidingSettings s;
  s.spatial_threshold = 200;
  std::vector<Vec3> points;
  Pcg32 rng(4);
  for (int k = 0; k < 40; ++k) points.emplace_back(rng.next_float(), rng.next_float() * 0.3f, rng.next_float());
  SpatialTree serial(unit_box()), threaded(unit_box());
  for (int it = 0; it < 3; ++it) {
    for (size_t k = 0; k < points.size(); ++k) record_at(serial, points[k], 100, 10 * it + k);
    std::vector<std::thread> threads;
    for (size_t t = 0; t < 2; ++t)
      threads.emplace_back([&, t] {
        for (size_t k = points.size() - 1 - t; k < points.size(); k -= 2) record_at(threaded, points[k], 100, 10 * it + k);
      });
    for (std::thread& t : threads) t.join();
    serial.end_iteration(4u << it, s);
    threaded.end_iteration(4u << it, s);
    ASSERT_TRUE(serial == threaded) << "iteration " << it;
  }
  EXPECT_GT(serial.leaf_count(), 8u);
}

// Adjoint-driven roulette reads them: the incident luminance over the sphere, the mean of the
// recorded values (each is Li / pdf), and the mean pixel sample; a split leaf's halves keep them.
TEST(SpatialTree, AnIterationLeavesEachLeafItsRadianceAndPixelEstimates) {
  GuidingSettings s;
  s.spatial_threshold = 2;  // (splits the leaf at the end of the iteration)
  SpatialTree tree(unit_box());
  const uint32_t leaf = tree.leaf_of(Vec3(0.3f));
  // Values exact in the fixed point: no rounding, so the estimates are exact too.
  for (float v : {1.f, 2.f, 0.f, 5.f}) tree.record(leaf, Vec3(0.f, 0.f, 1.f), v, 0.5f);
  for (float v : {0.25f, 0.75f}) tree.record_pixel(leaf, v, 0.5f);
  EXPECT_EQ(tree.radiance(leaf), 0.f) << "nothing before the iteration ends";
  tree.end_iteration(4, s);
  ASSERT_GT(tree.leaf_count(), 1u);
  for (Vec3 p : {Vec3(0.1f), Vec3(0.9f)}) {
    EXPECT_EQ(tree.radiance(tree.leaf_of(p)), 2.f);
    EXPECT_EQ(tree.pixel(tree.leaf_of(p)), 0.5f);
  }
  // Each iteration's own: the next one, without records, knows nothing.
  tree.end_iteration(8, s);
  EXPECT_EQ(tree.radiance(tree.leaf_of(Vec3(0.3f))), 0.f);
  EXPECT_EQ(tree.pixel(tree.leaf_of(Vec3(0.3f))), 0.f);
}

TEST(SpatialTree, NothingIsSplitBeyondTheMemoryCap) {
  GuidingSettings s;
  s.spatial_threshold = 10;
  s.max_bytes = SpatialTree(unit_box()).bytes() + 100;  // too small for a split
  SpatialTree tree(unit_box());
  for (int it = 0; it < 3; ++it) {
    record_at(tree, Vec3(0.3f), 5000, 5 + it);
    tree.end_iteration(4u << it, s);
  }
  EXPECT_EQ(tree.leaf_count(), 1u);
  EXPECT_LE(tree.bytes(), s.max_bytes);
  // It still guides, with the directions it could afford.
  float pdf = 0.f;
  const Vec3 d = tree.sampling(0).sample(Vec2(0.3f, 0.6f), pdf);
  EXPECT_TRUE(pdf > 0.f && std::isfinite(pdf));
  EXPECT_NEAR(length(d), 1.f, 1e-5f);
  // A larger cap lets it split.
  s.max_bytes = size_t(256) << 20;
  record_at(tree, Vec3(0.3f), 5000, 9);
  tree.end_iteration(32, s);
  EXPECT_GT(tree.leaf_count(), 1u);
}

}  // namespace
}  // namespace tessera
