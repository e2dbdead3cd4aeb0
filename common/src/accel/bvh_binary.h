// The binary SAH tree the 4-wide BVH is collapsed from (private to accel).
#pragma once

#include "accel/sah_binned.h"
#include "tessera/accel/bvh.h"
#include "tessera/core/bounds.h"

#include <cstdint>
#include <vector>

namespace tessera::accel_detail {

/// Depth-first binary node: the first child is the next node, the second at `second`; a leaf
/// (count > 0) covers refs [first, first + count) of the partitioned PrimRef array.
struct BinaryNode {
  Bounds3 bounds;
  uint32_t second = 0;  // interior only
  uint32_t first = 0;   // leaf only
  uint32_t count = 0;   // 0: interior
};

/// Builds the tree over `refs` (partitioned in place into leaf order). `block` is the SAH's leaf
/// granularity: a leaf of n primitives costs ceil(n / block) tests (4 for Tri4 packets, 1 for
/// spheres). Parallel in the caller's task arena; the result does not depend on the thread count.
HugeVector<BinaryNode> build_binary(HugeVector<PrimRef>& refs, uint32_t block);

/// Leaves of a binary tree in depth-first (array) order, with the first packet (or sphere) each
/// one gets when leaves take ceil(count / block) consecutive slots.
struct LeafSlots {
  std::vector<uint32_t> leaves;      // binary node indices
  std::vector<uint32_t> first_slot;  // per entry of `leaves`
  std::vector<uint32_t> refs;        // per binary node: the leaf's bvh_ref (leaves only)
  uint32_t total = 0;
};

LeafSlots assign_slots(const HugeVector<BinaryNode>& binary, uint32_t block);

/// The wide tree of a binary one: each wide node takes a binary node's children and repeatedly
/// opens the interior child of largest surface area until it has kBvhWidth (or only leaves remain).
/// `leaf_refs[i]` is the bvh_ref of binary leaf i (indexed like `binary`). Depth-first, first
/// interior child next, leaves in the binary tree's depth-first order; deterministic. A binary
/// root that is a leaf becomes a wide root with that one leaf.
NodeArray collapse_to_wide(const HugeVector<BinaryNode>& binary,
                                       const std::vector<uint32_t>& leaf_refs);

}  // namespace tessera::accel_detail
