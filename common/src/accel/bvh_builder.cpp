// Parallel, deterministic binned-SAH BVH construction and flattening.
//
// Determinism: every decision (bounds, bins, split, partition) depends only on the primitive range
// a node owns, never on scheduling. Large nodes build their children as tasks, each writing into its
// own node vector; the pieces are then placed depth-first in a fixed order. Parallel reductions use
// fixed chunks merged in chunk order (sah_binned.cpp). So nodes_ and prim_order_ are byte-identical
// for any number of threads.
#include "accel/sah_binned.h"
#include "tessera/accel/bvh.h"
#include "tessera/core/check.h"

#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <memory>

namespace tessera {
using namespace accel_detail;

namespace {

/// Deeper than this, nodes are split at the object median so the tree depth stays within the
/// traversal stack (64 entries; one far child is pushed per level at most).
constexpr int kMaxDepth = 56;

int ceil_log2(size_t n) {
  int k = 0;
  while ((size_t(1) << k) < n) ++k;
  return k;
}

BvhNode make_node(const Bounds3& b) {
  BvhNode node{};  // zeroes offset, count, axis, pad: node bytes must not depend on garbage
  node.lo = b.lo;
  node.hi = b.hi;
  return node;
}

/// A built subtree: either built serially into `nodes` (local depth-first layout, second-child
/// indices relative to the vector), or one interior node above the parallel threshold with two
/// subtrees.
struct Subtree {
  std::vector<BvhNode> nodes;
  BvhNode root{};
  std::unique_ptr<Subtree> left, right;
  uint32_t size = 0;  // nodes in the whole subtree
};

struct Decision {
  bool leaf = true;
  size_t mid = 0;
  int axis = 0;
};

class Builder {
 public:
  explicit Builder(PrimRef* refs) : refs_(refs) {}

  std::unique_ptr<Subtree> build_task(size_t begin, size_t end, int depth) {
    auto st = std::make_unique<Subtree>();
    const size_t n = end - begin;
    if (n <= kParallelThreshold) {
      // Roughly 2n/3 nodes for leaves of about 3 primitives.
      st->nodes.reserve(n);
      build_serial(begin, end, depth, st->nodes);
      st->size = uint32_t(st->nodes.size());
      return st;
    }
    const RangeBounds rb = compute_range_bounds(refs_ + begin, n, true);
    const Decision d = decide(begin, end, depth, rb, true);
    TESSERA_CHECK(!d.leaf);  // only nodes of <= kMaxLeafSize primitives become leaves
    st->root = make_node(rb.bounds);
    st->root.axis = uint8_t(d.axis);
    tbb::task_group group;
    group.run([&] { st->left = build_task(begin, d.mid, depth + 1); });
    st->right = build_task(d.mid, end, depth + 1);
    group.wait();
    st->size = 1 + st->left->size + st->right->size;
    return st;
  }

 private:
  uint32_t build_serial(size_t begin, size_t end, int depth, std::vector<BvhNode>& out) {
    const size_t n = end - begin;
    const RangeBounds rb = compute_range_bounds(refs_ + begin, n, false);
    TESSERA_DCHECK(depth < kMaxDepth + 4);  // the traversal stack holds 64 entries
    const uint32_t index = uint32_t(out.size());
    out.push_back(make_node(rb.bounds));
    const Decision d = decide(begin, end, depth, rb, false);
    if (d.leaf) {
      out[index].offset = uint32_t(begin);
      out[index].count = uint16_t(n);
      return index;
    }
    out[index].axis = uint8_t(d.axis);
    build_serial(begin, d.mid, depth + 1, out);
    const uint32_t second = build_serial(d.mid, end, depth + 1, out);
    out[index].offset = second;
    return index;
  }

  Decision decide(size_t begin, size_t end, int depth, const RangeBounds& rb, bool parallel) {
    const size_t n = end - begin;
    if (n == 1) return {};
    PrimRef* first = refs_ + begin;
    PrimRef* last = refs_ + end;
    if (depth + ceil_log2(n) < kMaxDepth) {
      const BinMapper mapper(rb.centroids, bin_count(n));
      const SahSplit split = find_sah_split(first, n, rb.bounds, mapper, parallel);
      if (split.valid) {
        if (n <= kMaxLeafSize && float(n) <= split.cost) return {};
        const int axis = split.axis, bin = split.bin;
        PrimRef* mid = std::partition(
            first, last, [&](const PrimRef& r) { return mapper.bin(r.centroid(), axis) <= bin; });
        TESSERA_DCHECK(mid != first && mid != last);
        return {false, size_t(mid - refs_), axis};
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
    return {false, size_t(mid - refs_), axis};
  }

  PrimRef* refs_;
};

struct CopyJob {
  const std::vector<BvhNode>* nodes;
  uint32_t base;
};

/// Writes the nodes above the parallel threshold and lists the serially built pieces with the
/// position each one gets in the depth-first array.
void place(const Subtree& st, uint32_t base, std::vector<BvhNode>& out, std::vector<CopyJob>& jobs) {
  if (!st.nodes.empty()) {
    jobs.push_back({&st.nodes, base});
    return;
  }
  BvhNode node = st.root;
  node.offset = base + 1 + st.left->size;
  out[base] = node;
  place(*st.left, base + 1, out, jobs);
  place(*st.right, node.offset, out, jobs);
}

bool valid_triangle(const std::array<Vec3, 3>& t) {
  if (!is_finite(t[0]) || !is_finite(t[1]) || !is_finite(t[2])) return false;
  const Vec3 n = cross(t[1] - t[0], t[2] - t[0]);
  return n.x != 0.f || n.y != 0.f || n.z != 0.f;
}

}  // namespace

Bvh Bvh::build(std::vector<std::array<Vec3, 3>> triangles, std::vector<SpherePrim> spheres) {
  Bvh bvh;
  TESSERA_CHECK(triangles.size() + spheres.size() < size_t(0xFFFFFFFFu));
  bvh.num_triangles_ = uint32_t(triangles.size());

  std::vector<PrimRef> refs;
  refs.reserve(triangles.size() + spheres.size());
  for (uint32_t i = 0; i < triangles.size(); ++i) {
    const auto& t = triangles[i];
    if (!valid_triangle(t)) continue;
    PrimRef r{};
    r.lo = vmin(t[0], vmin(t[1], t[2]));
    r.hi = vmax(t[0], vmax(t[1], t[2]));
    r.prim = i;
    refs.push_back(r);
  }
  for (uint32_t i = 0; i < spheres.size(); ++i) {
    const SpherePrim& s = spheres[i];
    if (!is_finite(s.center) || !std::isfinite(s.radius) || !(s.radius > 0.f)) continue;
    // A few ULPs of slack: c +- r rounds to nearest and could cut the sphere by half an ULP.
    const Vec3 r3(s.radius * (1.f + 4.f * std::numeric_limits<float>::epsilon()));
    PrimRef r{};
    r.lo = s.center - r3;
    r.hi = s.center + r3;
    r.prim = bvh.num_triangles_ + i;
    refs.push_back(r);
  }
  bvh.spheres_ = std::move(spheres);
  if (refs.empty()) return bvh;

  Builder builder(refs.data());
  std::unique_ptr<Subtree> tree = builder.build_task(0, refs.size(), 0);

  bvh.nodes_.resize(tree->size);
  std::vector<CopyJob> jobs;
  place(*tree, 0, bvh.nodes_, jobs);
  tbb::parallel_for(size_t(0), jobs.size(), [&](size_t j) {
    const CopyJob job = jobs[j];
    BvhNode* dst = bvh.nodes_.data() + job.base;
    for (size_t i = 0; i < job.nodes->size(); ++i) {
      BvhNode node = (*job.nodes)[i];
      if (node.count == 0) node.offset += job.base;
      dst[i] = node;
    }
  });
  tree.reset();

  const size_t n = refs.size();
  bvh.prim_order_.resize(n);
  bvh.tris_.resize(n);
  tbb::parallel_for(size_t(0), n, [&](size_t i) {
    const uint32_t prim = refs[i].prim;
    bvh.prim_order_[i] = prim;
    if (prim < bvh.num_triangles_) bvh.tris_[i] = triangles[prim];
  });
  return bvh;
}

BvhStats Bvh::stats() const {
  BvhStats s;
  s.nodes = nodes_.size();
  s.primitives = prim_order_.size();
  s.bytes = nodes_.size() * sizeof(BvhNode) + prim_order_.size() * sizeof(uint32_t) +
            tris_.size() * sizeof(tris_[0]) + spheres_.size() * sizeof(SpherePrim);
  if (nodes_.empty()) return s;
  const float root_area = Bounds3{nodes_[0].lo, nodes_[0].hi}.surface_area();
  const double inv_root = root_area > 0.f ? 1.0 / root_area : 0.0;
  double cost = 0;
  struct Item {
    uint32_t node;
    int depth;
  };
  std::vector<Item> stack{{0, 1}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    const BvhNode& node = nodes_[it.node];
    const double area = Bounds3{node.lo, node.hi}.surface_area() * inv_root;
    s.max_depth = std::max(s.max_depth, it.depth);
    if (node.count > 0) {
      ++s.leaves;
      cost += area * node.count;
    } else {
      cost += area * kTraversalCost;
      stack.push_back({it.node + 1, it.depth + 1});
      stack.push_back({node.offset, it.depth + 1});
    }
  }
  s.sah_cost = inv_root > 0 ? cost : 0;
  return s;
}

}  // namespace tessera
