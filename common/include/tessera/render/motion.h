// Moving geometry for motion blur.
//
// A shape whose `Shape::motion` is set keeps its geometry in OBJECT space and is left out of the
// scene's world-space BVH; Scene::finalize gives it a MotionInstance instead: a BVH over its
// object-space primitives and its world bounds over the shutter. A ray at time t that enters
// those bounds is taken to object space with world_from_object.at(t), intersected there (an
// affine map keeps the ray parameter t), and the hit is taken back to world space. Static scenes
// never get here: Scene only looks at instances when it has some.
// Instances are tested in a linear loop (after a slab test of their shutter bounds): right for a
// handful of moving objects; many would want a top-level BVH over those bounds.
#pragma once

#include "tessera/accel/bvh.h"
#include "tessera/core/animated_transform.h"

#include <cstdint>
#include <utility>

namespace tessera {

struct MotionInstance {
  const AnimatedTransform* world_from_object = nullptr;  // owned by the shape
  Bvh object_bvh;
  Bounds3 world_bounds;     // the shape's bounds over [shutter_open, shutter_close]
  uint32_t shape = 0;       // index in Scene::shapes
  uint32_t first_prim = 0;  // global primitive index of its first primitive
};

/// Ray `r` (world space) in the object space of `world_from_object`; same parametrisation.
inline Ray to_object_ray(const Ray& r, const Transform& world_from_object) {
  Ray o = r;
  Transform inv = world_from_object.inverse();
  o.o = inv.apply_point(r.o);
  o.d = inv.apply_vector(r.d);
  return o;
}

/// Slab test of a ray against a box over [ray.tmin, ray.tmax].
inline bool ray_hits_box(const Ray& r, const Bounds3& b) {
  float t0 = r.tmin, t1 = r.tmax;
  for (int a = 0; a < 3; ++a) {
    float inv = 1.f / r.d[a];
    float n = (b.lo[a] - r.o[a]) * inv, f = (b.hi[a] - r.o[a]) * inv;
    if (n > f) std::swap(n, f);
    // NaN (a zero direction component on the slab's edge) keeps the interval: conservative.
    t0 = n > t0 ? n : t0;
    t1 = f < t1 ? f : t1;
    if (t0 > t1) return false;
  }
  return true;
}

}  // namespace tessera
