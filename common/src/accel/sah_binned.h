// Binned surface-area-heuristic split search for the BVH builder (private to accel).
//
// Cost model (costs relative to one leaf test; a test covers `block` primitives, 4 for Tri4 packets):
//   leaf:     C_leaf  = B(n)                                 B(n) = ceil(n / block)
//   interior: C_split = kTraversalCost + (B(n_L) SA(L) + B(n_R) SA(R)) / SA(node)
// with kTraversalCost = 2. A node becomes a leaf when it fits one test, or when it holds at most
// kMaxLeafSize and C_leaf <= C_split. Splits are searched on kNumBins centroid bins per axis
// (fewer for small nodes, see bin_count). When no binned split separates the primitives (all
// centroids coincide), bvh_builder.cpp splits at the object median instead.
// Measured on the bathroom rays (wide tree, Tri4 packets): traversal cost 2 was a few percent faster
// than 0.5 and 1, 3 and 4 slower; a maximum leaf of 16 gave the same speed as 8 with fewer nodes.
#pragma once

#include "tessera/core/bounds.h"

#include <cstddef>
#include <cstdint>

namespace tessera::accel_detail {

inline constexpr int kNumBins = 32;
inline constexpr float kTraversalCost = 2.f;
inline constexpr uint32_t kMaxLeafSize = 8;
/// Nodes with more primitives than this bin in parallel and build their children as tasks.
inline constexpr size_t kParallelThreshold = 4096;
/// Fixed chunk size of the parallel reductions; independent of the thread count so the result is.
inline constexpr size_t kReduceChunk = 2048;

/// A primitive as the builder sees it: its bounds and global index. 32 bytes.
struct alignas(16) PrimRef {
  Vec3 lo;
  uint32_t prim;
  Vec3 hi;
  uint32_t pad;
  Vec3 centroid() const { return (lo + hi) * 0.5f; }
};
static_assert(sizeof(PrimRef) == 32);

/// Bounds of the primitives and of their centroids over a range.
struct RangeBounds {
  Bounds3 bounds;
  Bounds3 centroids;
};

/// Computes RangeBounds; chunked in parallel when `parallel` (same result either way).
RangeBounds compute_range_bounds(const PrimRef* refs, size_t n, bool parallel);

/// Bins for a node of n primitives: kNumBins, fewer for small nodes (a handful of primitives
/// cannot fill 32 bins, and the per-bin sweep would dominate their cost).
inline int bin_count(size_t n) { return n >= size_t(kNumBins) ? kNumBins : (n < 8 ? 8 : int(n)); }

/// Maps centroids to bins along one axis of a centroid box. The same instance classifies during
/// binning and during partitioning, so both agree exactly.
struct BinMapper {
  float lo[3], scale[3];
  bool usable[3];  // the centroid extent along the axis is non-zero and finite
  int num_bins;
  BinMapper(const Bounds3& centroids, int bins);
  /// Bin of centroid `c` on `axis`; the clamping mirrors the SSE binning loop bit for bit.
  int bin(Vec3 c, int axis) const {
    float f = (c[axis] - lo[axis]) * scale[axis];
    f = f > 0.f ? f : 0.f;
    const float last = float(num_bins - 1);
    f = f < last ? f : last;
    return int(f);
  }
};

struct SahSplit {
  bool valid = false;  // false: no binned split separates the primitives
  int axis = 0;
  int bin = 0;         // primitives with bin <= `bin` go left
  float cost = 0.f;    // C_split as above
};

/// Best binned SAH split, counting primitives in blocks of 2^block_shift; deterministic (ties go to
/// the lower axis, then the lower bin).
SahSplit find_sah_split(const PrimRef* refs, size_t n, const Bounds3& bounds, const BinMapper& mapper,
                        uint32_t block_shift, bool parallel);

}  // namespace tessera::accel_detail
