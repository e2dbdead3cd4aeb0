// Parallel, deterministic binned-SAH construction of the binary tree that bvh_collapse.cpp widens.
//
// Determinism: every decision (bounds, bins, split, partition) depends only on the primitive range
// a node owns, never on scheduling. Large nodes build their children as tasks, each writing into its
// own node vector; the pieces are then placed depth-first in a fixed order. Parallel reductions use
// fixed chunks merged in chunk order (sah_binned.cpp). So the nodes and the partitioned references
// are identical for any number of threads.
#include "accel/bvh_binary.h"
#include "tessera/core/check.h"

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <memory>

namespace tessera::accel_detail {
namespace {

/// Deeper than this, nodes are split at the object median so the tree stays within the traversal
/// stack (the wide tree is no deeper than this one, and pushes at most kBvhWidth - 1 children a level).
constexpr int kMaxDepth = 56;

int ceil_log2(size_t n) {
  int k = 0;
  while ((size_t(1) << k) < n) ++k;
  return k;
}

/// A built subtree: either built serially into `nodes` (local depth-first layout, second-child
/// indices relative to the vector), or one interior node above the parallel threshold with two
/// subtrees.
struct Subtree {
  HugeVector<BinaryNode> nodes;
  BinaryNode root{};
  std::unique_ptr<Subtree> left, right;
  uint32_t size = 0;  // nodes in the whole subtree
};

struct Decision {
  bool leaf = true;
  size_t mid = 0;
};

class Builder {
 public:
  Builder(PrimRef* refs, uint32_t block) : refs_(refs), block_shift_(block == 4 ? 2 : 0) {}

  std::unique_ptr<Subtree> build_task(size_t begin, size_t end, int depth) {
    auto st = std::make_unique<Subtree>();
    const size_t n = end - begin;
    if (n <= kParallelThreshold) {
      st->nodes.reserve(n / 2 + 1);
      build_serial(begin, end, depth, st->nodes);
      st->size = uint32_t(st->nodes.size());
      return st;
    }
    const RangeBounds rb = compute_range_bounds(refs_ + begin, n, true);
    const Decision d = decide(begin, end, depth, rb, true);
    TESSERA_CHECK(!d.leaf);  // only nodes of <= kMaxLeafSize primitives become leaves
    st->root.bounds = rb.bounds;
    tbb::task_group group;
    group.run([&] { st->left = build_task(begin, d.mid, depth + 1); });
    st->right = build_task(d.mid, end, depth + 1);
    group.wait();
    st->size = 1 + st->left->size + st->right->size;
    return st;
  }

 private:
  uint32_t build_serial(size_t begin, size_t end, int depth, HugeVector<BinaryNode>& out) {
    const size_t n = end - begin;
    const RangeBounds rb = compute_range_bounds(refs_ + begin, n, false);
    TESSERA_DCHECK(depth < kMaxDepth + 4);
    const uint32_t index = uint32_t(out.size());
    out.push_back(BinaryNode{rb.bounds, 0, 0, 0});
    const Decision d = decide(begin, end, depth, rb, false);
    if (d.leaf) {
      out[index].first = uint32_t(begin);
      out[index].count = uint32_t(n);
      return index;
    }
    build_serial(begin, d.mid, depth + 1, out);
    const uint32_t second = build_serial(d.mid, end, depth + 1, out);
    out[index].second = second;
    return index;
  }

  Decision decide(size_t begin, size_t end, int depth, const RangeBounds& rb, bool parallel) {
    const size_t n = end - begin;
    if (n == 1) return {};
    PrimRef* first = refs_ + begin;
    PrimRef* last = refs_ + end;
    if (n <= (size_t(1) << block_shift_)) return {};  // one packet: splitting cannot pay
    if (depth + ceil_log2(n) < kMaxDepth) {
      const BinMapper mapper(rb.centroids, bin_count(n));
      const SahSplit split = find_sah_split(first, n, rb.bounds, mapper, block_shift_, parallel);
      if (split.valid) {
        const float leaf_cost = float(blocks(uint32_t(n)));
        if (n <= kMaxLeafSize && leaf_cost <= split.cost) return {};
        const int axis = split.axis, bin = split.bin;
        PrimRef* mid = std::partition(
            first, last, [&](const PrimRef& r) { return mapper.bin(r.centroid(), axis) <= bin; });
        TESSERA_DCHECK(mid != first && mid != last);
        return {false, size_t(mid - refs_)};
      }
    }
    if (n <= kMaxLeafSize) return {};
    // All centroids coincide (or the depth budget is spent): object median along the widest
    // centroid axis, ties broken by primitive index so the order is fully determined.
    const int axis = max_dimension(rb.centroids.diagonal());
    PrimRef* mid = first + n / 2;
    std::nth_element(first, mid, last, [axis](const PrimRef& a, const PrimRef& b) {
      const float ca = a.centroid()[axis], cb = b.centroid()[axis];
      return ca < cb || (ca == cb && a.prim < b.prim);
    });
    return {false, size_t(mid - refs_)};
  }

  uint32_t blocks(uint32_t n) const { return (n + (1u << block_shift_) - 1) >> block_shift_; }

  PrimRef* refs_;
  uint32_t block_shift_;
};

struct CopyJob {
  const HugeVector<BinaryNode>* nodes;
  uint32_t base;
};

/// Writes the nodes above the parallel threshold and lists the serially built pieces with the
/// position each one gets in the depth-first array.
void place(const Subtree& st, uint32_t base, HugeVector<BinaryNode>& out, std::vector<CopyJob>& jobs) {
  if (!st.nodes.empty()) {
    jobs.push_back({&st.nodes, base});
    return;
  }
  BinaryNode node = st.root;
  node.second = base + 1 + st.left->size;
  out[base] = node;
  place(*st.left, base + 1, out, jobs);
  place(*st.right, node.second, out, jobs);
}

}  // namespace

HugeVector<BinaryNode> build_binary(HugeVector<PrimRef>& refs, uint32_t block) {
  TESSERA_CHECK(block == 1 || block == 4);
  if (refs.empty()) return {};
  Builder builder(refs.data(), block);
  std::unique_ptr<Subtree> tree = builder.build_task(0, refs.size(), 0);
  HugeVector<BinaryNode> nodes(tree->size);
  std::vector<CopyJob> jobs;
  place(*tree, 0, nodes, jobs);
  tbb::parallel_for(size_t(0), jobs.size(), [&](size_t j) {
    const CopyJob job = jobs[j];
    BinaryNode* dst = nodes.data() + job.base;
    for (size_t i = 0; i < job.nodes->size(); ++i) {
      BinaryNode node = (*job.nodes)[i];
      if (node.count == 0) node.second += job.base;
      dst[i] = node;
    }
  });
  return nodes;
}

}  // namespace tessera::accel_detail
