// The record an accelerator returns for a closest hit, before the shape completes it into a
// SurfaceInteraction (render/interaction.h).
#pragma once

#include "tessera/core/ray.h"

#include <cstdint>

namespace tessera {

/// For triangles (b1, b2) are the barycentric coordinates of v1 and v2; spheres leave them unused.
/// `prim` is the accelerator's global primitive index (accel/bvh.h).
struct Hit {
  float t = kInfinity;
  uint32_t prim = 0xFFFFFFFFu;
  float b1 = 0.f, b2 = 0.f;
};

}  // namespace tessera
