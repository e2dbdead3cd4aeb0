// Bvh::trace: the triangle tree of Tri4 packets, then the sphere tree (wide_traversal.h).
#include "accel/tri4_inline.h"
#include "accel/wide_traversal.h"
#include "tessera/accel/bvh.h"

namespace tessera {
using namespace accel_detail;

namespace {

/// A HitFilter with the ray it is asked about.
struct BoundFilter {
  const HitFilter* filter;
  const Ray* ray;
  bool operator()(const Hit& hit) const { return filter->blocks(*ray, hit); }
};

/// Triangles: leaves are runs of Tri4 packets.
template <int kz, bool kAnyHit, class Filter>
struct TriangleLeaves {
  const Tri4* packets;
  WatertightRay wr;
  WatertightRay4 r4;
  Filter blocks;
  TriangleLeaves(const Tri4* p, const Ray& ray, const Filter& f)
      : packets(p), wr(WatertightRay::make<kz>(ray)), r4(WatertightRay4::make(wr)), blocks(f) {}
  void prefetch(uint32_t ref) const {
    const char* p = reinterpret_cast<const char*>(packets + bvh_ref::leaf_first(ref));
    __builtin_prefetch(p);
    __builtin_prefetch(p + 64);
    __builtin_prefetch(p + 128);
  }
  bool intersect(uint32_t ref, const Ray& ray, float& tmax, Hit& hit) const {
    const Tri4* p = packets + bvh_ref::leaf_first(ref);
    const uint32_t count = bvh_ref::leaf_count(ref);
    bool found = false;
    for (uint32_t k = 0; k < count; ++k) {
      if (intersect_tri4<kz, kAnyHit>(p[k], wr, r4, ray.tmin, tmax, hit, blocks)) {
        if constexpr (kAnyHit) return true;
        found = true;
      }
    }
    return found;
  }
};

/// Spheres: leaves are runs of the leaf-ordered sphere array.
template <bool kAnyHit, class Filter>
struct SphereLeaves {
  const SpherePrim* spheres;
  const uint32_t* order;
  Filter blocks;
  void prefetch(uint32_t ref) const { __builtin_prefetch(spheres + bvh_ref::leaf_first(ref)); }
  bool intersect(uint32_t ref, const Ray& ray, float& tmax, Hit& hit) const {
    const uint32_t first = bvh_ref::leaf_first(ref), end = first + bvh_ref::leaf_count(ref);
    bool found = false;
    for (uint32_t i = first; i < end; ++i) {
      float t;
      if (!intersect_sphere_inline(ray, spheres[i].center, spheres[i].radius, ray.tmin, tmax, t)) continue;
      if constexpr (kAnyHit) {
        if (blocks(Hit{t, order[i], 0.f, 0.f})) return true;
        continue;
      }
      tmax = t;
      hit.t = t;
      hit.prim = order[i];
      hit.b1 = hit.b2 = 0.f;
      found = true;
    }
    return found;
  }
};

}  // namespace

template <bool kAnyHit, class Filter>
bool Bvh::trace(const Ray& ray, Hit& hit, const Filter& blocks) const {
  const BoxRay br = BoxRay::make(ray);  // shared by both trees
  float tmax = ray.tmax;
  bool found = false;
  if (!tri_nodes_.empty()) {
    const BvhNode* nodes = tri_nodes_.data();
    const Tri4* packets = packets_.data();
    bool h;
    switch (watertight_axis(ray.d)) {
      case 0: h = traverse<kAnyHit>(nodes, TriangleLeaves<0, kAnyHit, Filter>(packets, ray, blocks), ray, br, tmax, hit); break;
      case 1: h = traverse<kAnyHit>(nodes, TriangleLeaves<1, kAnyHit, Filter>(packets, ray, blocks), ray, br, tmax, hit); break;
      default: h = traverse<kAnyHit>(nodes, TriangleLeaves<2, kAnyHit, Filter>(packets, ray, blocks), ray, br, tmax, hit); break;
    }
    if (h) {
      if constexpr (kAnyHit) return true;
      found = true;
    }
  }
  if (!sphere_nodes_.empty() &&
      traverse<kAnyHit>(sphere_nodes_.data(),
                        SphereLeaves<kAnyHit, Filter>{leaf_spheres_.data(), sphere_order_.data(), blocks}, ray, br,
                        tmax, hit))
    found = true;
  return found;
}

bool Bvh::intersect(const Ray& ray, Hit& hit) const { return trace<false>(ray, hit, NoFilter{}); }

bool Bvh::occluded(const Ray& ray) const {
  Hit unused;
  return trace<true>(ray, unused, NoFilter{});
}

bool Bvh::occluded(const Ray& ray, const HitFilter& filter) const {
  Hit unused;
  return trace<true>(ray, unused, BoundFilter{&filter, &ray});
}

}  // namespace tessera
