// The learned BSDF fraction (guiding/bsdf_fraction.h): the candidate whose mixture best matches
// the product the samples carried wins, and the sums do not depend on the order of records.
#include "tessera/guiding/bsdf_fraction.h"
#include "tessera/guiding/spatial_tree.h"

#include "tessera/core/hash.h"

#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

namespace tessera {
namespace {

// A one-dimensional stand-in for directions on [0,1): the BSDF's pdf is uniform, the guide's 2x.
float bsdf_pdf(float) { return 1.f; }
float guide_pdf(float x) { return 2.f * x; }

struct Record {
  float weight, bsdf, guide;
};

// Samples drawn from the half-and-half mixture, each carrying product(x) over its pdf.
template <typename Product>
std::vector<Record> samples(Product&& product, int n, uint64_t seed) {
  Pcg32 rng(seed);
  std::vector<Record> out;
  for (int k = 0; k < n; ++k) {
    const float u = rng.next_float();
    const float x = rng.next_float() < 0.5f ? u : std::sqrt(u);  // (inverse of the guide's cdf x^2)
    const float pdf = 0.5f * bsdf_pdf(x) + 0.5f * guide_pdf(x);
    out.push_back({product(x) / pdf, bsdf_pdf(x), guide_pdf(x)});
  }
  return out;
}

float learned(const std::vector<Record>& records) {
  BsdfFractionLoss loss;
  for (const Record& r : records) loss.record(r.weight, r.bsdf, r.guide);
  return loss.best(0.5f);
}

TEST(BsdfFraction, TheMixtureClosestToTheProductWins) {
  // Light only where the guide points: guide as much as the candidates allow.
  EXPECT_FLOAT_EQ(learned(samples([](float x) { return 3.f * guide_pdf(x); }, 20000, 1)), 0.1f);
  // Light shaped like the BSDF: the BSDF alone.
  EXPECT_FLOAT_EQ(learned(samples([](float x) { return 0.7f * bsdf_pdf(x); }, 20000, 2)), 1.f);
  // Light shaped like a 0.3 / 0.7 mixture: the loss is flat near its minimum, so within a step.
  const float mixed = learned(samples([](float x) { return 0.3f * bsdf_pdf(x) + 0.7f * guide_pdf(x); }, 200000, 3));
  EXPECT_NEAR(mixed, 0.3f, 0.1001f);
}

TEST(BsdfFraction, ALowerBoundLimitsTheChoice) {
  BsdfFractionLoss loss;
  for (const Record& r : samples([](float x) { return 3.f * guide_pdf(x); }, 20000, 6)) loss.record(r.weight, r.bsdf, r.guide);
  EXPECT_FLOAT_EQ(loss.best(0.5f), 0.1f);
  EXPECT_FLOAT_EQ(loss.best(0.5f, 0.3f), 0.3f);
  EXPECT_FLOAT_EQ(loss.best(0.5f, 1.f), 1.f);
}

TEST(BsdfFraction, NothingRecordedKeepsTheCurrentFraction) {
  BsdfFractionLoss loss;
  EXPECT_EQ(loss.best(0.7f), 0.7f);
  loss.record(0.f, 1.f, 2.f);  // a sample that carried no light
  loss.record(std::nanf(""), 1.f, 2.f);
  EXPECT_EQ(loss.best(0.7f), 0.7f);
}

TEST(BsdfFraction, SumsDoNotDependOnTheOrderOfRecords) {
  const std::vector<Record> records = samples([](float x) { return 1.f + 100.f * x * x * x; }, 40000, 4);
  BsdfFractionLoss forward, threaded, halves[2];
  for (const Record& r : records) forward.record(r.weight, r.bsdf, r.guide);
  std::vector<std::thread> threads;
  for (int t = 0; t < 2; ++t)
    threads.emplace_back([&, t] {
      for (size_t i = size_t(t); i < records.size(); i += 2) {
        const Record& r = records[records.size() - 1 - i];
        threaded.record(r.weight, r.bsdf, r.guide);
        halves[t].record(r.weight, r.bsdf, r.guide);
      }
    });
  for (std::thread& t : threads) t.join();
  halves[1].merge(halves[0]);
  EXPECT_EQ(forward, threaded);
  EXPECT_EQ(forward, halves[1]);
}

TEST(BsdfFraction, EachLeafLearnsItsFractionAtTheEndOfAnIteration) {
  Bounds3 box;
  box.extend(Vec3(0.f));
  box.extend(Vec3(1.f));
  GuidingSettings s;
  s.spatial_threshold = 1e9;  // one leaf
  s.min_bsdf_fraction = 0.f;
  for (bool learn : {true, false}) {
    s.learn_bsdf_fraction = learn;
    SpatialTree tree(box, 0.5f);
    const uint32_t leaf = tree.leaf_of(Vec3(0.5f));
    for (const Record& r : samples([](float x) { return guide_pdf(x); }, 5000, 5))
      tree.record_fraction(leaf, r.weight, r.bsdf, r.guide);
    EXPECT_EQ(tree.bsdf_fraction(leaf), 0.5f);  // (only at the barrier)
    tree.end_iteration(4, s);
    EXPECT_FLOAT_EQ(tree.bsdf_fraction(leaf), learn ? 0.1f : 0.5f);
    // The next iteration starts from nothing: without records the fraction stays.
    tree.end_iteration(8, s);
    EXPECT_FLOAT_EQ(tree.bsdf_fraction(leaf), learn ? 0.1f : 0.5f);
  }
}

}  // namespace
}  // namespace tessera
