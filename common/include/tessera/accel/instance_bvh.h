// Two-level acceleration: a wide BVH over instances, each an object-space Bvh placed in the world by
// a transform (Mitsuba's shapegroup + instance, and moving shapes for motion blur).
//
// Only the top level is per instance: a shapegroup's BVH is built once and shared by all of its
// instances, so memory grows with the number of distinct groups, not with the number of placements.
// A ray that enters an instance's world box is taken to object space (an affine map keeps the ray
// parameter t, so distances compare across instances) and traced there; Hit::inst names the instance,
// Hit::prim the primitive in its BVH's own numbering.
// Static instances keep object_from_world as a float 3x4 matrix (one matrix-vector product per
// instance entered). A moving instance evaluates its AnimatedTransform at the ray's time.
// Determinism: the top level is built like Bvh (binned SAH, same bytes for any thread count); among
// hits at exactly the same distance the first one found is kept, as in Bvh.
#pragma once

#include "tessera/accel/bvh.h"
#include "tessera/core/animated_transform.h"
#include "tessera/core/transform.h"

#include <cstdint>
#include <vector>

namespace tessera {

/// One placement of an object-space BVH.
struct BvhInstance {
  const Bvh* bvh = nullptr;                      // not owned; shared by the group's instances
  Transform world_from_object;                   // static instances
  const AnimatedTransform* motion = nullptr;     // not owned; set for a moving instance
  Bounds3 world_bounds;                          // over the shutter for a moving instance
};

/// The float affine map a static instance applies to rays (rows of object_from_world).
struct Affine3 {
  float m[3][4];
  static Affine3 from(const Transform& t);
  Vec3 point(Vec3 p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3], m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  Vec3 vector(Vec3 v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
};

class InstanceBvh {
 public:
  InstanceBvh() = default;
  /// Instances with an empty or non-finite world box never hit; Hit::inst is the index in `instances`.
  static InstanceBvh build(const std::vector<BvhInstance>& instances);

  /// Closest hit with t in [ray.tmin, ray.tmax]; sets hit (inst included) and returns true if any.
  bool intersect(const Ray& ray, Hit& hit) const;
  /// Any hit with t in [ray.tmin, ray.tmax].
  bool occluded(const Ray& ray) const;

  bool empty() const { return leaves_.empty(); }
  size_t size() const { return leaves_.size(); }
  Bounds3 bounds() const { return bounds_; }
  /// Bytes of the top level (nodes and leaf records), not of the instanced BVHs.
  size_t bytes() const;

  /// What a top-level leaf slot holds (in leaf order): the instance and how to reach its object space.
  struct Leaf {
    const Bvh* bvh;
    const AnimatedTransform* motion;  // null: `object_from_world` is the map
    Affine3 object_from_world;
    uint32_t index;                   // in the build's input
  };

 private:
  template <bool kAnyHit>
  bool trace(const Ray& ray, Hit& hit) const;

  NodeArray nodes_;
  std::vector<Leaf> leaves_;
  Bounds3 bounds_;
};

/// Ray `r` (world space) in the object space of `world_from_object`; same parametrisation.
Ray to_object_ray(const Ray& r, const Transform& world_from_object);

}  // namespace tessera
