// The record an accelerator returns for a closest hit, before the shape completes it into a
// SurfaceInteraction (render/interaction.h).
#pragma once

#include "tessera/core/ray.h"

#include <cstdint>

namespace tessera {

/// For triangles (b1, b2) are the barycentric coordinates of v1 and v2; spheres leave them unused.
/// `prim` is the global primitive index of the BVH that was hit (accel/bvh.h); for a hit through an
/// instance (accel/instance_bvh.h) that is the instance's object-space BVH, and `inst` says which.
struct Hit {
  static constexpr uint32_t kNoInstance = 0xFFFFFFFFu;
  float t = kInfinity;
  uint32_t prim = 0xFFFFFFFFu;
  float b1 = 0.f, b2 = 0.f;
  uint32_t inst = kNoInstance;
};

}  // namespace tessera
