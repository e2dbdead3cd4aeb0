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
  Vec3 p_error;        // conservative bound on |p - exact hit| per axis (pbrt-v4's Point3fi
                       // interval); zero means p is exact. Spawned rays offset by it.
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

/// pbrt's gamma(n): bound on the relative error of n chained float roundings (round to nearest,
/// no FMA contraction, as the build's -ffp-contract=off guarantees).
constexpr float error_gamma(int n) {
  constexpr float eps = 0.5f * 1.1920928955078125e-7f;  // unit roundoff of float
  return (float(n) * eps) / (1.f - float(n) * eps);
}

/// Error bound of p0 b0 + p1 b1 + p2 b2 evaluated in float with b0 = 1 - b1 - b2 (b_i >= 0):
/// pbrt-v4's gamma(7) (|b0 p0| + |b1 p1| + |b2 p2|) for the products and sums, plus gamma(3) for
/// the rounding of b0: weights summing to 1 + delta scale the point by 1 + delta, off the plane.
inline Vec3 barycentric_point_error(Vec3 p0, Vec3 p1, Vec3 p2, float b0, float b1, float b2) {
  return (vabs(p0 * b0) + vabs(p1 * b1) + vabs(p2 * b2)) * error_gamma(10);
}

/// pbrt-v4's OffsetRayOrigin: moves `p` (exact up to `p_error` per axis) along the geometric
/// normal `n` to the side `w` points to, by the projection of the error box on the normal, so the
/// origin lies strictly beyond the surface whatever the rounding of p was; each moved coordinate
/// is then rounded away from the surface. The offset follows the hit's own rounding error, so it
/// is small near the origin, at small scales and on thin features alike.
Vec3 offset_ray_origin(Vec3 p, Vec3 p_error, Vec3 n, Vec3 w);

/// Ray leaving `p` (error bound `p_error`, geometric normal `ng`) in direction `d`.
Ray spawn_ray(Vec3 p, Vec3 p_error, Vec3 ng, Vec3 d);
inline Ray spawn_ray(const SurfaceInteraction& si, Vec3 d) { return spawn_ray(si.p, si.p_error, si.ng, d); }

/// Shadow-ray segment between two surface points, both ends offset off their surfaces (pbrt-v4's
/// SpawnRayTo between interactions): direction pt - po (not normalised), t in [0, 1 - epsilon].
/// `target_n` zero: the target is a point off any surface (a point light), used as is.
Ray spawn_ray_to(Vec3 p, Vec3 p_error, Vec3 ng, Vec3 target, Vec3 target_error, Vec3 target_n);
inline Ray spawn_ray_to(const SurfaceInteraction& si, Vec3 target, Vec3 target_error, Vec3 target_n) {
  return spawn_ray_to(si.p, si.p_error, si.ng, target, target_error, target_n);
}

/// Callers that only have a point and a normal (no error bound): the error is estimated as that of
/// a point interpolated from vertices of p's own magnitude (error_gamma(7) * max |p_i| on every
/// axis). Exact for hit points whose triangle is not much larger than its distance to the world
/// origin; prefer the overloads above, which use the hit's actual bound.
Vec3 estimated_point_error(Vec3 p);
/// Compatibility overloads (point, normal) with the estimated error; the target of spawn_ray_to is
/// not offset, so that segment stops 1e-4 of its length short of it (pbrt's ShadowEpsilon).
Ray spawn_ray(Vec3 p, Vec3 ng, Vec3 d);
Ray spawn_ray_to(Vec3 p, Vec3 ng, Vec3 target);

}  // namespace tessera
