// Instancing and moving geometry: shapes placed in the world by a transform instead of being
// transformed into it.
//
// Two kinds of shapes keep OBJECT-space geometry and stay out of the scene's world-space BVH:
// - members of a shapegroup (Shape::group set). Each group gets one BVH over its members, built
//   once; every ShapeInstance of the group places it with its own world_from_object, which may move
//   over the shutter. Memory grows with the groups, not the instances.
// - moving shapes (Shape::motion set, motion blur): each is a group of one placed by its motion.
// Scene::finalize puts all placements under one top-level BVH (accel/instance_bvh.h). A ray that
// enters an instance is intersected in object space at its time (an affine map keeps the ray
// parameter t), and the hit is taken back to world space.
// Orientation follows Mitsuba 3's instances: positions by world_from_object, normals by its inverse
// transpose, so a mirroring instance does not turn its shapes inside out (a mirroring to_world on a
// shape outside any group does: its geometric normal comes from the world-space winding).
#pragma once

#include "tessera/core/animated_transform.h"

#include <cstdint>

namespace tessera {

/// One placement of a shapegroup: its members (Shape::group == group) at world_from_object.
struct ShapeInstance {
  uint32_t group = 0;
  AnimatedTransform world_from_object;  // static unless the instance moves over the shutter
};

}  // namespace tessera
