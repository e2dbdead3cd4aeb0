// BVH traversal: closest hit and any hit. No allocation, no exceptions.
//
// At an interior node both children's boxes are tested; the nearer hit child (by box entry
// distance) is visited first and the other pushed with its entry distance, so a popped subtree
// entered beyond the closest hit so far is skipped without touching its node.
// The slab test is the robust one of Ize, "Robust BVH Ray Traversal" (JCGT 2013), as in pbrt-v4:
// each slab distance carries at most three roundings, so scaling the exit distance by 1 + 2 gamma(3)
// keeps every box the ray truly crosses, and a watertight triangle hit is never culled by its box.
#include "accel/intersect_inline.h"
#include "tessera/accel/bvh.h"
#include "tessera/core/check.h"

namespace tessera {
using namespace accel_detail;

namespace {

constexpr int kStackSize = 64;
constexpr float kExitScale = 1.f + 2.f * gamma(3);

/// Reciprocal that never produces inf: a zero (or denormal) direction component becomes +-1e30,
/// so (plane - origin) * inv is never 0 * inf = NaN. A box plane containing an axis-parallel ray
/// then counts as crossed, which is conservative.
inline float safe_rcp(float d) {
  constexpr float kTiny = 1e-30f;
  return std::abs(d) < kTiny ? std::copysign(1.f / kTiny, d) : 1.f / d;
}

struct BoxRay {
  Vec3 o, inv;
};

/// True when the node box overlaps the ray segment [tmin, tmax]; `tnear` gets the entry distance.
inline bool hit_box(const BvhNode& n, const BoxRay& r, float tmin, float tmax, float& tnear) {
  const float tx0 = (n.lo.x - r.o.x) * r.inv.x, tx1 = (n.hi.x - r.o.x) * r.inv.x;
  const float ty0 = (n.lo.y - r.o.y) * r.inv.y, ty1 = (n.hi.y - r.o.y) * r.inv.y;
  const float tz0 = (n.lo.z - r.o.z) * r.inv.z, tz1 = (n.hi.z - r.o.z) * r.inv.z;
  const float t0 = std::max(std::max(tmin, std::min(tx0, tx1)),
                            std::max(std::min(ty0, ty1), std::min(tz0, tz1)));
  const float exit = std::min(std::max(tx0, tx1), std::min(std::max(ty0, ty1), std::max(tz0, tz1)));
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

template <int kz, bool kAnyHit>
bool traverse(const BvhView& v, const Ray& ray, Hit& hit) {
  const WatertightRay wr = WatertightRay::make<kz>(ray);
  const BoxRay br{ray.o, Vec3(safe_rcp(ray.d.x), safe_rcp(ray.d.y), safe_rcp(ray.d.z))};
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
