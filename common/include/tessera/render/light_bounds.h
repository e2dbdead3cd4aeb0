// Spatial and directional bounds of what a light (or a cluster of lights) emits, and the
// importance estimate a light hierarchy descends by (pbrt-v4's LightBounds, after Conty Estevez and
// Kulla, "Importance Sampling of Many Lights with Adaptive Tree Splitting", 2018).
//
// Emission leaves the box `bounds` in directions within theta_o + theta_e of the axis `w`:
// theta_o bounds the spread of the emitters' normals (0 for one flat triangle, pi for a point or a
// sphere), theta_e the spread of emission about each normal (pi/2 for a diffuse surface). A
// two-sided emitter also emits about -w.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/vec.h"

namespace tessera {

/// A cone of directions: axis `w` (unit) and cos of its half-angle; cos_theta = -1 is the sphere.
struct DirectionCone {
  Vec3 w{0.f, 0.f, 1.f};
  float cos_theta = 1.f;
  static DirectionCone sphere() { return {{0.f, 0.f, 1.f}, -1.f}; }
};

/// Smallest cone (of the form this construction gives) containing both.
DirectionCone merge(const DirectionCone& a, const DirectionCone& b);

/// Cone of the directions from `p` towards points of `b` (the sphere if p is inside b).
DirectionCone bound_subtended_directions(const Bounds3& b, Vec3 p);

struct LightBounds {
  Bounds3 bounds;
  Vec3 w{0.f, 0.f, 1.f};
  float phi = 0.f;          // emitted power (Light::power())
  float cos_theta_o = 1.f;  // normal spread
  float cos_theta_e = 0.f;  // emission spread about each normal
  bool two_sided = false;

  Vec3 centroid() const { return bounds.center(); }
  /// Conservative estimate of how much this cluster contributes at `p` with surface normal `n`
  /// (n = 0 in a medium: no cosine factor). 0 only where no emitter in it can reach p's side.
  /// Allocation-free, never throws; the same inputs always give the same float.
  float importance(Vec3 p, Vec3 n) const;
};

/// Bounds of the union of two clusters (powers add). An empty (phi == 0, empty box) operand
/// returns the other.
LightBounds merge(const LightBounds& a, const LightBounds& b);

}  // namespace tessera
