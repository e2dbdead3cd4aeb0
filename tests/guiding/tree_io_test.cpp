// The SD-tree as bytes (guiding/tree_io.h): a tree reads back as itself, training records split
// among recorders add up to the tree that recorded everything itself, and damaged bytes are
// refused without changing anything.
#include "tessera/guiding/tree_io.h"

#include "tessera/core/hash.h"
#include "tessera/core/sampling.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

// Records `n` random directions at random points; the same `seed` records the same.
void record_some(SpatialTree& tree, int n, uint64_t seed) {
  Pcg32 rng(seed);
  for (int k = 0; k < n; ++k) {
    const uint32_t leaf = tree.leaf_of(Vec3(rng.next_float(), rng.next_float(), rng.next_float()));
    tree.record(leaf, square_to_uniform_sphere(Vec2(rng.next_float(), rng.next_float())), rng.next_float() * 10.f,
                rng.next_float());
    tree.record_fraction(leaf, rng.next_float(), rng.next_float(), rng.next_float());
    if (k % 3 == 0) tree.record_pixel(leaf, rng.next_float() * 2.f, rng.next_float());
    if (k % 5 == 0) tree.record_gain(rng.next_float() * 4.0, rng.next_float(), rng.next_float());
  }
}

// A trained tree: a few iterations of records, so that both levels have split.
SpatialTree trained_tree() {
  Bounds3 box;
  box.extend(Vec3(0.f));
  box.extend(Vec3(1.f));
  SpatialTree tree(box);
  GuidingSettings s;
  s.spatial_threshold = 300;
  s.gain_paths = 1;  // (a few hundred paths decide)
  for (int it = 0; it < 3; ++it) {
    record_some(tree, 4000, uint64_t(it));
    tree.end_iteration(4u << it, s);
  }
  return tree;
}

TEST(TreeIo, ATreeReadsBackAsItself) {
  const SpatialTree tree = trained_tree();
  EXPECT_GT(tree.leaf_count(), 4u);
  SpatialTree back;
  std::string error;
  ASSERT_TRUE(read_tree(write_tree(tree), back, error)) << error;
  EXPECT_TRUE(back == tree);
}

TEST(TreeIo, AGuideThatSteppedAsideReadsBackAsItself) {
  SpatialTree tree = trained_tree();
  EXPECT_GT(tree.predicted_gain(), 1.3f) << "decided at the iteration of 8 spp, and kept guiding";
  GuidingSettings s;
  s.min_gain = 1e6;
  s.gain_paths = 1;
  for (int k = 0; k < 10; ++k) tree.record_gain(1.0, 1.0, 0.5f);
  SpatialTree fresh = tree;
  SpatialTree never_decided(Bounds3(Vec3(0.f), Vec3(1.f)));
  for (int k = 0; k < 10; ++k) never_decided.record_gain(1.0, 1.0, 0.5f);
  never_decided.end_iteration(8, s);
  ASSERT_TRUE(never_decided.stepped_aside());
  SpatialTree back;
  std::string error;
  ASSERT_TRUE(read_tree(write_tree(never_decided), back, error)) << error;
  EXPECT_TRUE(back == never_decided);
  EXPECT_TRUE(back.stepped_aside());
  EXPECT_FLOAT_EQ(back.predicted_gain(), 1.f);
  fresh.end_iteration(32, s);
  EXPECT_FALSE(fresh.stepped_aside()) << "decided once";
}

TEST(TreeIo, RecordsSplitAmongRecordersAddUpToRecordingEverything) {
  const SpatialTree base = trained_tree();
  SpatialTree direct = base, merged = base;
  record_some(direct, 3000, 11);
  record_some(direct, 3000, 12);
  // Two "tiles", each into its own recorder, added in the other order.
  SpatialTree a = make_recorder(base), b = make_recorder(base);
  record_some(a, 3000, 11);
  record_some(b, 3000, 12);
  std::string error;
  ASSERT_TRUE(add_records(merged, write_records(b), error)) << error;
  ASSERT_TRUE(add_records(merged, write_records(a), error)) << error;
  EXPECT_TRUE(merged == direct);
  GuidingSettings s;
  direct.end_iteration(32, s);
  merged.end_iteration(32, s);
  EXPECT_TRUE(merged == direct) << "the next tree is the same";
  EXPECT_LT(write_records(a).size(), write_tree(base).size()) << "records are sparse";
}

TEST(TreeIo, DamagedBytesAreRefusedAndChangeNothing) {
  const SpatialTree base = trained_tree();
  const std::string tree_bytes = write_tree(base);
  SpatialTree recorder = make_recorder(base);
  record_some(recorder, 500, 3);
  const std::string records = write_records(recorder);
  std::string error;
  SpatialTree out;
  EXPECT_FALSE(read_tree(tree_bytes.substr(0, tree_bytes.size() - 1), out, error));
  EXPECT_FALSE(read_tree(tree_bytes + "x", out, error));
  // Every flipped byte of the records: refused (the tree unchanged) or, where it only changes a
  // value, taken; never outside the tree's cells.
  int refused = 0;
  for (size_t i = 0; i < records.size(); i += 7) {
    std::string bad = records;
    bad[i] ^= 0x40;
    SpatialTree target = base;
    if (!add_records(target, bad, error)) {
      EXPECT_TRUE(target == base) << "byte " << i;
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  // Records of another tree's cells do not fit.
  SpatialTree small(Bounds3{Vec3(0.f), Vec3(1.f)});
  EXPECT_FALSE(add_records(small, records, error));
  EXPECT_NE(error.find("training records"), std::string::npos) << error;
  // Damaged trees, byte by byte: refused or read, never a crash, and what is read is traversable.
  for (size_t i = 0; i < tree_bytes.size(); i += 13) {
    std::string bad = tree_bytes;
    bad[i] ^= 0x21;
    if (read_tree(bad, out, error)) (void)out.leaf_of(Vec3(0.5f));
  }
}

}  // namespace
}  // namespace tessera
