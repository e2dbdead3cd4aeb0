// Flattened binned-SAH bounding volume hierarchy over triangles and spheres.
//
// Primitive numbering ("global primitive index"): triangles 0..T-1 in the order given to build(),
// then spheres T..T+S-1. Hit::prim reports that index.
// Layout: nodes in one depth-first array, 32 bytes each; an interior node's first child is the next
// node, its second child is at `second_child`; a leaf covers a contiguous range of the reordered
// primitive array. Triangles are copied into leaf order so a leaf's vertices are contiguous.
// Build is parallel (oneTBB, in the caller's task arena) and deterministic: the same input gives
// the same node bytes whatever the thread count.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/ray.h"
#include "tessera/core/vec.h"
#include "tessera/render/shape.h"

#include <array>
#include <cstdint>
#include <vector>

namespace tessera {

struct SpherePrim {
  Vec3 center;
  float radius = 0.f;
};

struct alignas(32) BvhNode {
  Vec3 lo;                 // 12 bytes
  uint32_t offset;         // leaf: first primitive (in leaf order); interior: second child index
  Vec3 hi;                 // 12 bytes
  uint16_t count;          // primitives in the leaf; 0 for an interior node
  uint8_t axis;            // split axis of an interior node (for near-first traversal)
  uint8_t pad;
};
static_assert(sizeof(BvhNode) == 32);

struct BvhStats {
  size_t nodes = 0, leaves = 0, bytes = 0, primitives = 0;
  int max_depth = 0;
  double sah_cost = 0;
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

  Bounds3 bounds() const { return nodes_.empty() ? Bounds3{} : Bounds3{nodes_[0].lo, nodes_[0].hi}; }
  BvhStats stats() const;
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  /// Leaf-order position -> global primitive index.
  const std::vector<uint32_t>& prim_order() const { return prim_order_; }

 private:
  std::vector<BvhNode> nodes_;
  std::vector<uint32_t> prim_order_;
  std::vector<std::array<Vec3, 3>> tris_;   // in leaf order (only triangle entries used)
  std::vector<SpherePrim> spheres_;          // indexed by global index - num_triangles
  uint32_t num_triangles_ = 0;
};

/// Watertight ray/triangle test (Woop, Benthin, Wald 2013). Returns true and sets t, b1, b2 when
/// the ray hits the triangle within (tmin, tmax).
bool intersect_triangle(const Ray& ray, Vec3 p0, Vec3 p1, Vec3 p2, float& t, float& b1, float& b2);
/// Ray/sphere test with a numerically careful quadratic; nearest t in (tmin, tmax).
bool intersect_sphere(const Ray& ray, Vec3 center, float radius, float& t);

}  // namespace tessera
