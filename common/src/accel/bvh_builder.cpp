// Bvh::build: primitive references, the binary SAH trees (bvh_binary_builder.cpp), their leaves
// packed into Tri4 packets or leaf-ordered spheres, and the wide trees (bvh_collapse.cpp).
#include "accel/bvh_binary.h"
#include "tessera/accel/bvh.h"
#include "tessera/core/check.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace tessera {

namespace accel_detail {

LeafSlots assign_slots(const HugeVector<BinaryNode>& binary, uint32_t block) {
  LeafSlots s;
  s.refs.assign(binary.size(), bvh_ref::kEmpty);
  uint64_t next = 0;
  for (uint32_t i = 0; i < binary.size(); ++i) {
    if (binary[i].count == 0) continue;
    const uint32_t slots = (binary[i].count + block - 1) / block;
    TESSERA_CHECK(slots <= bvh_ref::kMaxCount && next + slots <= bvh_ref::kMaxFirst);
    s.leaves.push_back(i);
    s.first_slot.push_back(uint32_t(next));
    s.refs[i] = bvh_ref::leaf(uint32_t(next), slots);
    next += slots;
  }
  s.total = uint32_t(next);
  return s;
}

}  // namespace accel_detail

using namespace accel_detail;

namespace {

bool valid_triangle(const std::array<Vec3, 3>& t) {
  if (!is_finite(t[0]) || !is_finite(t[1]) || !is_finite(t[2])) return false;
  const Vec3 n = cross(t[1] - t[0], t[2] - t[0]);
  return n.x != 0.f || n.y != 0.f || n.z != 0.f;
}

/// References of the valid triangles, in input order; made in parallel over fixed chunks (count,
/// then fill at each chunk's offset), so the order does not depend on the thread count.
HugeVector<PrimRef> triangle_refs(const std::vector<std::array<Vec3, 3>>& triangles) {
  constexpr size_t kChunk = 4096;
  const size_t n = triangles.size(), chunks = (n + kChunk - 1) / kChunk;
  std::vector<uint32_t> valid(chunks);
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    uint32_t c = 0;
    for (size_t i = k * kChunk, end = std::min(n, i + kChunk); i < end; ++i) c += valid_triangle(triangles[i]) ? 1 : 0;
    valid[k] = c;
  });
  std::vector<size_t> offset(chunks + 1, 0);
  for (size_t k = 0; k < chunks; ++k) offset[k + 1] = offset[k] + valid[k];
  HugeVector<PrimRef> refs(offset[chunks]);
  tbb::parallel_for(size_t(0), chunks, [&](size_t k) {
    size_t out = offset[k];
    for (size_t i = k * kChunk, end = std::min(n, i + kChunk); i < end; ++i) {
      const auto& t = triangles[i];
      if (!valid_triangle(t)) continue;
      PrimRef& r = refs[out++];
      r.lo = vmin(t[0], vmin(t[1], t[2]));
      r.hi = vmax(t[0], vmax(t[1], t[2]));
      r.prim = uint32_t(i);
      r.pad = 0;
    }
  });
  return refs;
}

Bounds3 root_bounds(const HugeVector<BinaryNode>& binary) { return binary.empty() ? Bounds3{} : binary[0].bounds; }

}  // namespace

Bvh Bvh::build(std::vector<std::array<Vec3, 3>> triangles, std::vector<SpherePrim> spheres) {
  Bvh bvh;
  TESSERA_CHECK(triangles.size() + spheres.size() < size_t(0xFFFFFFFFu));
  const uint32_t num_triangles = uint32_t(triangles.size());

  HugeVector<PrimRef> tri_refs = triangle_refs(triangles);
  HugeVector<PrimRef> sphere_refs;
  for (uint32_t i = 0; i < spheres.size(); ++i) {
    const SpherePrim& s = spheres[i];
    if (!is_finite(s.center) || !std::isfinite(s.radius) || !(s.radius > 0.f)) continue;
    // A few ULPs of slack: c +- r rounds to nearest and could cut the sphere by half an ULP.
    const Vec3 r3(s.radius * (1.f + 4.f * std::numeric_limits<float>::epsilon()));
    PrimRef r{};
    r.lo = s.center - r3;
    r.hi = s.center + r3;
    r.prim = num_triangles + i;
    sphere_refs.push_back(r);
  }

  // Triangles: packets of four in leaf order.
  const HugeVector<BinaryNode> tri_binary = build_binary(tri_refs, 4);
  const LeafSlots tri_slots = assign_slots(tri_binary, 4);
  bvh.packets_.resize(tri_slots.total);
  tbb::parallel_for(size_t(0), tri_slots.leaves.size(), [&](size_t k) {
    const BinaryNode& leaf = tri_binary[tri_slots.leaves[k]];
    Tri4* packet = bvh.packets_.data() + tri_slots.first_slot[k];
    for (uint32_t j = 0; j < (leaf.count + 3) / 4 * 4; ++j) {
      Tri4& p = packet[j / 4];
      const uint32_t lane = j % 4;
      if (j >= leaf.count) {
        p.prim[lane] = Tri4::kNoPrim;
        for (auto& vertex : p.v)
          for (auto& axis : vertex) axis[lane] = 0.f;
        continue;
      }
      const uint32_t prim = tri_refs[leaf.first + j].prim;
      p.prim[lane] = prim;
      for (int v = 0; v < 3; ++v)
        for (int a = 0; a < 3; ++a) p.v[v][a][lane] = triangles[prim][v][a];
    }
  });
  bvh.tri_nodes_ = collapse_to_wide(tri_binary, tri_slots.refs);

  // Spheres: one leaf-order array.
  const HugeVector<BinaryNode> sphere_binary = build_binary(sphere_refs, 1);
  const LeafSlots sphere_slots = assign_slots(sphere_binary, 1);
  bvh.leaf_spheres_.resize(sphere_refs.size());
  bvh.sphere_order_.resize(sphere_refs.size());
  for (size_t i = 0; i < sphere_refs.size(); ++i) {
    bvh.sphere_order_[i] = sphere_refs[i].prim;
    bvh.leaf_spheres_[i] = spheres[sphere_refs[i].prim - num_triangles];
  }
  bvh.sphere_nodes_ = collapse_to_wide(sphere_binary, sphere_slots.refs);

  bvh.bounds_ = merge(root_bounds(tri_binary), root_bounds(sphere_binary));
  return bvh;
}

namespace {

struct TreeStats {
  size_t leaves = 0;
  int max_depth = 0;
  double cost = 0;  // sum of area * cost, not yet divided by the root area
};

/// Leaves, depth and SAH cost of one wide tree; a leaf costs one test per packet (or sphere).
TreeStats tree_stats(const NodeArray& nodes) {
  TreeStats s;
  if (nodes.empty()) return s;
  struct Item {
    uint32_t node;
    int depth;
    float area;
  };
  Bounds3 root;
  for (int slot = 0; slot < BvhNode::kWidth; ++slot) root = merge(root, nodes[0].child_bounds(slot));
  std::vector<Item> stack{{0, 1, root.surface_area()}};
  while (!stack.empty()) {
    const Item it = stack.back();
    stack.pop_back();
    s.max_depth = std::max(s.max_depth, it.depth);
    s.cost += it.area;  // one node test for every ray entering the node's box
    const BvhNode& node = nodes[it.node];
    for (int slot = 0; slot < BvhNode::kWidth; ++slot) {
      const uint32_t ref = node.child[slot];
      if (ref == bvh_ref::kEmpty) continue;
      const float area = node.child_bounds(slot).surface_area();
      if (bvh_ref::is_leaf(ref)) {
        ++s.leaves;
        s.cost += double(area) * bvh_ref::leaf_count(ref);
      } else {
        stack.push_back({ref, it.depth + 1, area});
      }
    }
  }
  return s;
}

}  // namespace

BvhStats Bvh::stats() const {
  BvhStats s;
  s.nodes = tri_nodes_.size() + sphere_nodes_.size();
  s.packets = packets_.size();
  size_t triangles = 0;
  for (const Tri4& p : packets_)
    for (uint32_t prim : p.prim) triangles += prim != Tri4::kNoPrim ? 1 : 0;
  s.primitives = triangles + leaf_spheres_.size();
  s.bytes = s.nodes * sizeof(BvhNode) + packets_.size() * sizeof(Tri4) +
            leaf_spheres_.size() * (sizeof(SpherePrim) + sizeof(uint32_t));
  const TreeStats t = tree_stats(tri_nodes_), sp = tree_stats(sphere_nodes_);
  s.leaves = t.leaves + sp.leaves;
  s.max_depth = std::max(t.max_depth, sp.max_depth);
  const float area = bounds_.surface_area();
  s.sah_cost = area > 0.f ? (t.cost + sp.cost) / double(area) : 0.0;
  return s;
}

}  // namespace tessera
