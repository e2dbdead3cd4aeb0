// Wide BVH traversal, generic over what a leaf holds (private to accel): closest hit and any hit.
// No allocation, no exceptions. A `Leaves` type provides prefetch(ref) and
// intersect(ref, ray, tmax, hit), which shrinks tmax to a closer hit it finds.
//
// One SIMD slab test covers a node's children (AVX for 8-wide nodes, SSE2 for 4-wide: bvh.h). The children hit are visited nearest first
// (by box entry distance); the others are pushed with their entry distance, so a popped subtree
// entered beyond the closest hit so far is skipped without touching its node (as Embree's single-
// ray traversal does).
// The slab test is the robust one of Ize, "Robust BVH Ray Traversal" (JCGT 2013), as in pbrt-v4:
// each slab distance carries at most three roundings, so scaling the exit distances by 1 + 2 gamma(3)
// keeps every box the ray truly crosses, and a watertight triangle hit is never culled by its box.
// A zero direction component has an infinite reciprocal, and its slab distance is 0 * inf = NaN
// when the origin lies on that slab's plane (the ray runs inside the plane, so the slab does not
// bound it). maxps/minps return their second operand when either is NaN, and the second operand is
// always the running tmin/tmax side, so a NaN slab is dropped, never propagated.
#pragma once

#include "accel/intersect_inline.h"
#include "tessera/accel/bvh.h"
#include "tessera/core/check.h"

#include <immintrin.h>

namespace tessera::accel_detail {

inline constexpr int W = BvhNode::kWidth;
// W - 1 pushes a level at most; the binary tree it came from is at most ~60 levels deep.
inline constexpr int kStackSize = 64 * (W - 1);

/// The few SIMD operations of the slab test, W lanes wide.
#if defined(__AVX2__)
using VFloat = __m256;
inline VFloat vset1(float f) { return _mm256_set1_ps(f); }
inline VFloat vload(const float* p) { return _mm256_load_ps(p); }
inline VFloat vsub(VFloat a, VFloat b) { return _mm256_sub_ps(a, b); }
inline VFloat vmul(VFloat a, VFloat b) { return _mm256_mul_ps(a, b); }
inline VFloat vmax(VFloat a, VFloat b) { return _mm256_max_ps(a, b); }
inline VFloat vmin(VFloat a, VFloat b) { return _mm256_min_ps(a, b); }
inline int vle_mask(VFloat a, VFloat b) { return _mm256_movemask_ps(_mm256_cmp_ps(a, b, _CMP_LE_OQ)); }
inline void vstore(float* p, VFloat a) { _mm256_store_ps(p, a); }
#else
using VFloat = __m128;
inline VFloat vset1(float f) { return _mm_set1_ps(f); }
inline VFloat vload(const float* p) { return _mm_load_ps(p); }
inline VFloat vsub(VFloat a, VFloat b) { return _mm_sub_ps(a, b); }
inline VFloat vmul(VFloat a, VFloat b) { return _mm_mul_ps(a, b); }
inline VFloat vmax(VFloat a, VFloat b) { return _mm_max_ps(a, b); }
inline VFloat vmin(VFloat a, VFloat b) { return _mm_min_ps(a, b); }
inline int vle_mask(VFloat a, VFloat b) { return _mm_movemask_ps(_mm_cmple_ps(a, b)); }
inline void vstore(float* p, VFloat a) { _mm_store_ps(p, a); }
#endif
static_assert(sizeof(VFloat) == W * sizeof(float));
// The exit distances use a reciprocal pre-multiplied by the scale: one rounding more on the far
// side than pbrt-v4's (far - o) * inv * scale, so the bound is 2 gamma(4) instead of 2 gamma(3).
inline constexpr float kExitScale = 1.f + 2.f * accel_detail::gamma(4);

/// Per-ray constants of the slab test: which row of BvhNode::bounds is the near plane on each
/// axis (lo when the direction component is positive), origin and reciprocal direction broadcast.
struct BoxRay {
  VFloat o[3], inv[3], inv_far[3];
  int near[3];  // row of the near plane; the far plane is near ^ 1
  static BoxRay make(const Ray& ray) {
    BoxRay r;
    for (int a = 0; a < 3; ++a) {
      const float inv = 1.f / ray.d[a];
      r.o[a] = vset1(ray.o[a]);
      r.inv[a] = vset1(inv);
      r.inv_far[a] = vset1(inv * kExitScale);
      r.near[a] = 2 * a + (inv < 0.f ? 1 : 0);
    }
    return r;
  }
};

/// Mask of the children whose box overlaps [tmin, tmax]; `tnear` gets their entry distances.
inline int hit_children(const BvhNode& n, const BoxRay& r, VFloat tmin, VFloat tmax, float tnear[W]) {
  const VFloat nx = vmul(vsub(vload(n.bounds[r.near[0]]), r.o[0]), r.inv[0]);
  const VFloat ny = vmul(vsub(vload(n.bounds[r.near[1]]), r.o[1]), r.inv[1]);
  const VFloat nz = vmul(vsub(vload(n.bounds[r.near[2]]), r.o[2]), r.inv[2]);
  const VFloat fx = vmul(vsub(vload(n.bounds[r.near[0] ^ 1]), r.o[0]), r.inv_far[0]);
  const VFloat fy = vmul(vsub(vload(n.bounds[r.near[1] ^ 1]), r.o[1]), r.inv_far[1]);
  const VFloat fz = vmul(vsub(vload(n.bounds[r.near[2] ^ 1]), r.o[2]), r.inv_far[2]);
  const VFloat t0 = vmax(nx, vmax(ny, vmax(nz, tmin)));
  const VFloat t1 = vmin(fx, vmin(fy, vmin(fz, tmax)));
  vstore(tnear, t0);
  return vle_mask(t0, t1);
}

struct Entry {
  uint32_t ref;
  float tnear;
};

/// Starts loading what a hit child will need: an interior node's cache lines, or a leaf's first
/// packet. The tree does not fit in cache for real scenes, and a child is usually visited soon.
template <class Leaves>
inline void prefetch_child(const BvhNode* nodes, const Leaves& leaves, uint32_t ref) {
  if (bvh_ref::is_leaf(ref)) {
    leaves.prefetch(ref);
    return;
  }
  const char* p = reinterpret_cast<const char*>(nodes + ref);
  for (size_t line = 0; line < sizeof(BvhNode); line += 64) __builtin_prefetch(p + line);
}

/// Pushes the hit children of a node; returns the nearest to visit next (the others on the stack,
/// nearer ones above farther ones).
inline uint32_t order_children(const BvhNode& node, int mask, const float tnear[W], Entry* stack, int& sp) {
  const int i = __builtin_ctz(unsigned(mask));
  mask &= mask - 1;
  if (mask == 0) return node.child[i];
  const int j = __builtin_ctz(unsigned(mask));
  mask &= mask - 1;
  if (mask == 0) {
    if (tnear[j] < tnear[i]) {
      stack[sp++] = {node.child[i], tnear[i]};
      return node.child[j];
    }
    stack[sp++] = {node.child[j], tnear[j]};
    return node.child[i];
  }
  // Three or more: push all, insertion-sort them by decreasing distance, take the nearest.
  const int base = sp;
  stack[sp++] = {node.child[i], tnear[i]};
  stack[sp++] = {node.child[j], tnear[j]};
  while (mask) {
    const int k = __builtin_ctz(unsigned(mask));
    mask &= mask - 1;
    stack[sp++] = {node.child[k], tnear[k]};
  }
  for (int a = base + 1; a < sp; ++a) {
    const Entry e = stack[a];
    int b = a - 1;
    for (; b >= base && stack[b].tnear < e.tnear; --b) stack[b + 1] = stack[b];
    stack[b + 1] = e;
  }
  return stack[--sp].ref;
}

template <bool kAnyHit, class Leaves>
bool traverse(const BvhNode* nodes, const Leaves& leaves, const Ray& ray, const BoxRay& br, float& tmax, Hit& hit) {
  const VFloat tmin_v = vset1(ray.tmin);
  Entry stack[kStackSize];
  int sp = 0;
  uint32_t ref = 0;
  bool found = false;
  alignas(32) float tnear[W];
  for (;;) {
    while (!bvh_ref::is_leaf(ref)) {
      const BvhNode& node = nodes[ref];
      int mask = hit_children(node, br, tmin_v, vset1(tmax), tnear);
      if (mask == 0) goto pop;
      for (int m = mask; m; m &= m - 1) prefetch_child(nodes, leaves, node.child[__builtin_ctz(unsigned(m))]);
      TESSERA_DCHECK(sp + W <= kStackSize);
      if constexpr (kAnyHit) {
        // Any hit ends the search, so there is no closest hit to cull with: skip the sort.
        ref = node.child[__builtin_ctz(unsigned(mask))];
        for (mask &= mask - 1; mask; mask &= mask - 1) {
          const int k = __builtin_ctz(unsigned(mask));
          stack[sp++] = {node.child[k], tnear[k]};
        }
      } else {
        ref = order_children(node, mask, tnear, stack, sp);
      }
    }
    if (leaves.intersect(ref, ray, tmax, hit)) {
      if constexpr (kAnyHit) return true;
      found = true;
    }
  pop:
    // The next subtree, skipping those entered beyond the closest hit found so far.
    do {
      if (sp == 0) return found;
      --sp;
    } while (stack[sp].tnear > tmax);
    ref = stack[sp].ref;
  }
}

}  // namespace tessera::accel_detail
