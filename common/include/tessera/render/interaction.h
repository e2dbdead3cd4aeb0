// What the integrator knows about a ray's hit on a surface.
#pragma once

#include "tessera/core/frame.h"
#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

#include <cstdint>

namespace tessera {

class Shape;
class Bsdf;
class Light;

struct SurfaceInteraction {
  Vec3 p;              // world-space hit point
  float t = kInfinity; // ray distance
  Vec3 ng;             // geometric normal, unit, world space; faces the shape's outside (winding
                       // order / outward for analytic shapes, flipped by flip_normals)
  Frame shading;       // shading frame; shading.n is the interpolated normal, on ng's side
  Vec2 uv;
  // World-space dp/du and dp/dv (texture-space position derivatives, unnormalised); the bump and
  // normal maps build their tangent frames from them. Shapes without a usable parameterisation
  // give an orthonormal tangent pair of ng. The defaults match the default shading frame.
  Vec3 dpdu{1.f, 0.f, 0.f};
  Vec3 dpdv{0.f, 1.f, 0.f};
  Vec3 wo;             // unit direction back towards the ray origin (world)
  const Shape* shape = nullptr;
  uint32_t prim = 0;   // triangle index within the shape

  const Bsdf* bsdf() const;
  const Light* area_light() const;
  Vec3 to_local(Vec3 w) const { return shading.to_local(w); }
  Vec3 to_world(Vec3 w) const { return shading.to_world(w); }
};

/// Reconciles the interpolated shading normal with the geometry for a viewer in `wo_world`, as the
/// integrators need at every vertex. When the viewer is on one side of the geometric surface and on
/// the other of the shading one, Mitsuba 0.6 with `strictNormals` drops the vertex (returns false);
/// otherwise Tessera shades that hit with the geometric normal instead, so such pixels are not black
/// (the "black seams" of strongly interpolated or bumped normals).
bool reconcile_shading_frame(SurfaceInteraction& si, Vec3 wo_world, bool strict_normals);

/// True when direction `wi_world` (`wi_local` in the shading frame) is on the same side of the
/// geometric and of the shading surface. Integrators drop light and BSDF samples that are not:
/// light from behind the geometry would otherwise leak through a surface its shading normal tilts
/// towards.
inline bool consistent_side(const SurfaceInteraction& si, Vec3 wi_world, Vec3 wi_local) {
  return dot(si.ng, wi_world) * wi_local.z > 0.f;
}

/// Wächter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection" (Ray Tracing Gems,
/// ch. 6): moves `p` off the surface along `n` by a few ULPs scaled to |p|, so a new ray starting
/// there neither re-hits its own surface nor tunnels through a thin neighbour.
Vec3 offset_ray_origin(Vec3 p, Vec3 n);

/// Ray leaving `p` (on a surface with geometric normal `ng`) in direction `d`, origin offset to the
/// side `d` points to.
Ray spawn_ray(Vec3 p, Vec3 ng, Vec3 d);
/// Shadow-ray segment from surface point `p` towards `target`; stops just short of the target.
Ray spawn_ray_to(Vec3 p, Vec3 ng, Vec3 target);

}  // namespace tessera
