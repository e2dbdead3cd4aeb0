// Orthonormal frame around a normal. Local ("shading") coordinates put the normal on +z, so
// cos(theta) = v.z: every BSDF works in such a frame.
#pragma once

#include "tessera/core/vec.h"

#include <cmath>

namespace tessera {

/// Duff et al. 2017, "Building an Orthonormal Basis, Revisited": branchless and continuous.
inline void coordinate_system(Vec3 n, Vec3& s, Vec3& t) {
  float sign = std::copysign(1.f, n.z);
  float a = -1.f / (sign + n.z);
  float b = n.x * n.y * a;
  s = Vec3(1.f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  t = Vec3(b, sign + n.y * n.y * a, -n.y);
}

struct Frame {
  Vec3 s, t, n;
  Frame() : s(1, 0, 0), t(0, 1, 0), n(0, 0, 1) {}
  explicit Frame(Vec3 normal) : n(normal) { coordinate_system(n, s, t); }
  Vec3 to_local(Vec3 v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
  Vec3 to_world(Vec3 v) const { return s * v.x + t * v.y + n * v.z; }
};

inline float cos_theta(Vec3 w) { return w.z; }
inline float abs_cos_theta(Vec3 w) { return std::abs(w.z); }
inline bool same_hemisphere(Vec3 a, Vec3 b) { return a.z * b.z > 0.f; }

}  // namespace tessera
