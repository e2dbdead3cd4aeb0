// BVH traversal: closest hit and any hit. No allocation, no exceptions.
//
// At an interior node both children's boxes are tested; the nearer hit child (by box entry
// distance) is visited first and the other pushed with its entry distance, so a popped subtree
// entered beyond the closest hit so far is skipped without touching its node. (Ordering by the
// direction's sign on the node's split axis needs no comparison, but once both boxes are tested the
// entry distances are free, order better, and make the pop-time culling possible; on the bathroom
// rays this was as fast for primary rays and about 5% faster for diffuse and shadow rays.)
// The slab test is the robust one of Ize, "Robust BVH Ray Traversal" (JCGT 2013), as in pbrt-v4:
// each slab distance carries at most three roundings, so scaling the exit distance by 1 + 2 gamma(3)
// keeps every box the ray truly crosses, and a watertight triangle hit is never culled by its box.
#include "accel/intersect_inline.h"
#include "tessera/accel/bvh.h"
#include "tessera/core/check.h"

#include <cstddef>

namespace tessera {
using namespace accel_detail;

namespace {

constexpr int kStackSize = 64;
constexpr float kExitScale = 1.f + 2.f * gamma(3);

/// Per-ray constants of the slab test. The sign of each direction component decides which of
/// a box's two planes the ray meets first, so the test reads the near and far plane directly instead
/// of ordering the two slab distances with min/max.
struct BoxRay {
  Vec3 o, inv;
  int near[3], far[3];  // index of the near/far plane coordinate in the node's floats (see below)
};

// A node read as floats: lo.x lo.y lo.z [offset] hi.x hi.y hi.z [count, axis, pad].
static_assert(offsetof(BvhNode, lo) == 0 && offsetof(BvhNode, hi) == 4 * sizeof(float));

inline BoxRay make_box_ray(const Ray& ray) {
  BoxRay r{ray.o, Vec3(1.f / ray.d.x, 1.f / ray.d.y, 1.f / ray.d.z), {}, {}};
  for (int a = 0; a < 3; ++a) {
    r.near[a] = r.inv[a] < 0.f ? 4 + a : a;
    r.far[a] = r.inv[a] < 0.f ? a : 4 + a;
  }
  return r;
}

/// True when the node box overlaps the ray segment [tmin, tmax]; `tnear` gets the entry distance.
///
/// A zero direction component has an infinite reciprocal, and its slab distance is 0 * inf = NaN
/// when the origin lies exactly on that slab's plane (the ray runs inside the plane). std::max(a, b)
/// is (a < b) ? b : a and std::min(a, b) is (b < a) ? b : a, so with tmin and tmax (never NaN)
/// taking part as below, a NaN is dropped rather than propagated; it may take one other slab with
/// it, which only makes the test more conservative.
inline bool hit_box(const BvhNode& n, const BoxRay& r, float tmin, float tmax, float& tnear) {
  const float* f = &n.lo.x;
  const float tx0 = (f[r.near[0]] - r.o.x) * r.inv.x, tx1 = (f[r.far[0]] - r.o.x) * r.inv.x;
  const float ty0 = (f[r.near[1]] - r.o.y) * r.inv.y, ty1 = (f[r.far[1]] - r.o.y) * r.inv.y;
  const float tz0 = (f[r.near[2]] - r.o.z) * r.inv.z, tz1 = (f[r.far[2]] - r.o.z) * r.inv.z;
  const float t0 = std::max(std::max(tmin, tx0), std::max(ty0, tz0));
  const float exit = std::min(tx1, std::min(ty1, tz1));
  const float t1 = std::min(tmax, exit * kExitScale);
  tnear = t0;
  return t0 <= t1;
}

/// The BVH's arrays, passed to the traversal kernels (which are templates on the triangle test's
/// projection axis, so they cannot be declared in the public header).
struct BvhView {
  const BvhNode* nodes;
  const uint32_t* order;
  const std::array<Vec3, 3>* tris;
  const SpherePrim* spheres;
  uint32_t num_triangles;
  bool triangles_only;
};

/// A hit leaf child's triangles will be needed soon: start loading them while the traversal goes
/// on (a few percent faster on the bathroom rays, where the tree does not fit in cache).
inline void prefetch_leaf(const BvhView& v, const BvhNode& n) {
  if (n.count == 0) return;
  __builtin_prefetch(&v.tris[n.offset]);
  __builtin_prefetch(&v.tris[n.offset + n.count - 1][2]);
}

template <int kz, bool kAnyHit>
bool traverse(const BvhView& v, const Ray& ray, Hit& hit) {
  const WatertightRay wr = WatertightRay::make<kz>(ray);
  const BoxRay br = make_box_ray(ray);
  const float tmin = ray.tmin;
  float tmax = ray.tmax;
  float tnear;
  if (!hit_box(v.nodes[0], br, tmin, tmax, tnear)) return false;

  struct Entry {
    uint32_t node;
    float tnear;
  };
  Entry stack[kStackSize];
  int sp = 0;
  uint32_t current = 0;
  bool found = false;
  for (;;) {
    const BvhNode& node = v.nodes[current];
    if (node.count == 0) {
      uint32_t a = current + 1, b = node.offset;
      float ta, tb;
      const bool hit_a = hit_box(v.nodes[a], br, tmin, tmax, ta);
      const bool hit_b = hit_box(v.nodes[b], br, tmin, tmax, tb);
      if (hit_a) prefetch_leaf(v, v.nodes[a]);
      if (hit_b) prefetch_leaf(v, v.nodes[b]);
      if (hit_a && hit_b) {
        if (tb < ta) {
          std::swap(a, b);
          std::swap(ta, tb);
        }
        TESSERA_DCHECK(sp < kStackSize);
        stack[sp++] = {b, tb};
        current = a;
        continue;
      }
      if (hit_a) {
        current = a;
        continue;
      }
      if (hit_b) {
        current = b;
        continue;
      }
    } else {
      const uint32_t end = node.offset + node.count;
      for (uint32_t i = node.offset; i < end; ++i) {
        float t, b1 = 0.f, b2 = 0.f;
        bool h;
        if (v.triangles_only || v.order[i] < v.num_triangles) {
          const auto& tri = v.tris[i];
          h = intersect_triangle_k<kz>(wr, tri[0], tri[1], tri[2], tmin, tmax, t, b1, b2);
        } else {
          const SpherePrim& s = v.spheres[v.order[i] - v.num_triangles];
          h = intersect_sphere_inline(ray, s.center, s.radius, tmin, tmax, t);
        }
        if (h) {
          if constexpr (kAnyHit) return true;
          tmax = t;
          hit.t = t;
          hit.prim = v.order[i];
          hit.b1 = b1;
          hit.b2 = b2;
          found = true;
        }
      }
    }
    // Pop the next subtree, skipping those entered beyond the closest hit found so far.
    for (;;) {
      if (sp == 0) return found;
      --sp;
      if (stack[sp].tnear <= tmax) {
        current = stack[sp].node;
        break;
      }
    }
  }
}

template <bool kAnyHit>
bool dispatch(const BvhView& v, const Ray& ray, Hit& hit) {
  switch (watertight_axis(ray.d)) {
    case 0: return traverse<0, kAnyHit>(v, ray, hit);
    case 1: return traverse<1, kAnyHit>(v, ray, hit);
    default: return traverse<2, kAnyHit>(v, ray, hit);
  }
}

}  // namespace

bool Bvh::intersect(const Ray& ray, Hit& hit) const {
  if (nodes_.empty()) return false;
  const BvhView v{nodes_.data(), prim_order_.data(), tris_.data(), spheres_.data(), num_triangles_,
                  spheres_.empty()};
  return dispatch<false>(v, ray, hit);
}

bool Bvh::occluded(const Ray& ray) const {
  if (nodes_.empty()) return false;
  const BvhView v{nodes_.data(), prim_order_.data(), tris_.data(), spheres_.data(), num_triangles_,
                  spheres_.empty()};
  Hit unused;
  return dispatch<true>(v, ray, unused);
}

}  // namespace tessera
