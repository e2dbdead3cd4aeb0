// Flattened wide SAH bounding volume hierarchy over triangles and spheres.
//
// Primitive numbering ("global primitive index"): triangles 0..T-1 in the order given to build(),
// then spheres T..T+S-1. Hit::prim reports that index.
//
// Build: a binned-SAH binary tree (parallel, oneTBB, in the caller's task arena), collapsed into a
// kBvhWidth-wide tree by pulling the largest-area grandchildren up into each node. Deterministic:
// the same input gives the same bytes whatever the thread count.
// Layout: triangles and spheres each have a tree of BvhNode in one depth-first array. A node holds
// its (up to) kBvhWidth children's boxes in SoA order, so one SIMD instruction tests a ray against
// all of them; its first interior child is the next node, the others are at the indices in `child`.
// Triangle leaves are runs of Tri4 packets (four triangles' vertices in SoA order, tested together),
// contiguous in depth-first order; sphere leaves are runs of the leaf-ordered sphere array.
//
// Width: the instruction set is fixed at build time (CMake TESSERA_SIMD, never -march=native):
// `avx2` (the default) gives 8-wide nodes tested with AVX, as Embree does on such CPUs; `sse2`, the
// x86-64 baseline, gives 4-wide nodes. Box tests are conservative and triangle tests bit-identical
// in both, so the width changes speed, not the image (up to which of two hits at exactly the same
// distance is reported).
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/hit.h"
#include "tessera/core/huge_page_allocator.h"
#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

#include <array>
#include <cstdint>
#include <vector>

namespace tessera {

struct SpherePrim {
  Vec3 center;
  float radius = 0.f;
};

/// A child reference: an interior node's index, or (kLeafBit set) a leaf of `leaf_count` packets
/// (triangle tree) or spheres (sphere tree) starting at `leaf_first`. An unused child slot is an
/// empty leaf with an empty box (lo = +inf, hi = -inf), which no ray enters.
namespace bvh_ref {
inline constexpr uint32_t kLeafBit = 0x80000000u;
inline constexpr int kCountShift = 27;
inline constexpr uint32_t kMaxCount = 15;
inline constexpr uint32_t kMaxFirst = (1u << kCountShift) - 1;
inline constexpr uint32_t kEmpty = kLeafBit;
constexpr bool is_leaf(uint32_t ref) { return (ref & kLeafBit) != 0; }
constexpr uint32_t leaf(uint32_t first, uint32_t count) { return kLeafBit | (count << kCountShift) | first; }
constexpr uint32_t leaf_first(uint32_t ref) { return ref & kMaxFirst; }
constexpr uint32_t leaf_count(uint32_t ref) { return (ref >> kCountShift) & kMaxCount; }
}  // namespace bvh_ref

#if defined(__AVX2__)
inline constexpr int kBvhWidth = 8;
#else
inline constexpr int kBvhWidth = 4;
#endif

template <int W>
struct alignas(64) BvhNodeW {
  static constexpr int kWidth = W;
  float bounds[6][W];  // rows lo.x, hi.x, lo.y, hi.y, lo.z, hi.z; column = child slot
  uint32_t child[W];   // bvh_ref encoding
  uint32_t pad[W];     // zero: node bytes must not depend on garbage
  Bounds3 child_bounds(int slot) const {
    return Bounds3{Vec3(bounds[0][slot], bounds[2][slot], bounds[4][slot]),
                   Vec3(bounds[1][slot], bounds[3][slot], bounds[5][slot])};
  }
};
using BvhNode = BvhNodeW<kBvhWidth>;
static_assert(sizeof(BvhNodeW<4>) == 128 && sizeof(BvhNodeW<8>) == 256);

/// Four triangles in SoA order: v[vertex][axis][lane]. A lane with prim == kNoPrim is unused.
struct alignas(16) Tri4 {
  static constexpr uint32_t kNoPrim = 0xFFFFFFFFu;
  float v[3][3][4];
  uint32_t prim[4];  // global primitive index
};
static_assert(sizeof(Tri4) == 160);

using Tri4Array = HugeVector<Tri4>;
using NodeArray = HugeVector<BvhNode>;

struct BvhStats {
  size_t nodes = 0, leaves = 0, bytes = 0, primitives = 0;
  size_t packets = 0;  // Tri4 packets (triangle lanes used: primitives minus spheres)
  int max_depth = 0;
  double sah_cost = 0;  // of the wide trees: node visits + packet tests per ray, by area
};

/// Lets an any-hit query pass through some primitives (cut-outs): `flagged` has a bit per global
/// primitive (bit p % 64 of word p / 64). A candidate hit on a flagged primitive goes to
/// `occludes(ctx, ray, hit)`, which decides whether it blocks the ray (and may accumulate what the
/// ray crossed in ctx); hits on other primitives block. Each primitive the ray crosses within
/// [tmin, tmax] is offered at most once, in an order fixed by the ray and the tree.
struct HitFilter {
  const uint64_t* flagged = nullptr;
  bool (*occludes)(void* ctx, const Ray& ray, const Hit& hit) = nullptr;
  void* ctx = nullptr;
  bool blocks(const Ray& ray, const Hit& hit) const {
    return !(flagged[hit.prim >> 6] >> (hit.prim & 63) & 1) || occludes(ctx, ray, hit);
  }
};

class Bvh {
 public:
  Bvh() = default;
  /// Degenerate (zero-area) or non-finite triangles are kept out of the tree; they never hit.
  static Bvh build(std::vector<std::array<Vec3, 3>> triangles, std::vector<SpherePrim> spheres);

  /// Closest hit with t in [ray.tmin, ray.tmax]; fills `hit` and returns true if any.
  bool intersect(const Ray& ray, Hit& hit) const;
  /// Any hit with t in [ray.tmin, ray.tmax].
  bool occluded(const Ray& ray) const;
  /// Any hit with t in [ray.tmin, ray.tmax] that `filter` says blocks the ray.
  bool occluded(const Ray& ray, const HitFilter& filter) const;

  Bounds3 bounds() const { return bounds_; }
  BvhStats stats() const;

  const NodeArray& tri_nodes() const { return tri_nodes_; }
  const Tri4Array& packets() const { return packets_; }
  const NodeArray& sphere_nodes() const { return sphere_nodes_; }
  /// Sphere leaf-order position -> global primitive index.
  const std::vector<uint32_t>& sphere_order() const { return sphere_order_; }

 private:
  /// Both traversals (bvh_traversal.cpp): the triangle tree, then the sphere tree with the closest
  /// distance found so far.
  template <bool kAnyHit, class Filter>
  bool trace(const Ray& ray, Hit& hit, const Filter& filter) const;

  NodeArray tri_nodes_;
  Tri4Array packets_;
  NodeArray sphere_nodes_;
  std::vector<SpherePrim> leaf_spheres_;   // in leaf order
  std::vector<uint32_t> sphere_order_;     // global index of leaf_spheres_[i]
  Bounds3 bounds_;
};

/// Watertight ray/triangle test (Woop, Benthin, Wald 2013). Returns true and sets t, b1, b2 when
/// the ray hits the triangle within (tmin, tmax].
bool intersect_triangle(const Ray& ray, Vec3 p0, Vec3 p1, Vec3 p2, float& t, float& b1, float& b2);
/// Ray/sphere test with a numerically careful quadratic; nearest t in (tmin, tmax].
bool intersect_sphere(const Ray& ray, Vec3 center, float radius, float& t);

}  // namespace tessera
