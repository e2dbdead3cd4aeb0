#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

namespace tessera {

/// Axis-aligned box; the default box is empty (min > max) so that `extend` works from scratch.
struct Bounds3 {
  Vec3 lo{kInfinity, kInfinity, kInfinity};
  Vec3 hi{-kInfinity, -kInfinity, -kInfinity};

  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  void extend(Vec3 p) { lo = vmin(lo, p); hi = vmax(hi, p); }
  void extend(const Bounds3& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
  Vec3 diagonal() const { return hi - lo; }
  Vec3 center() const { return (lo + hi) * 0.5f; }
  float surface_area() const {
    if (empty()) return 0.f;
    Vec3 d = diagonal();
    return 2.f * (d.x * d.y + d.y * d.z + d.z * d.x);
  }
  bool contains(Vec3 p) const {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
  }
};

inline Bounds3 merge(Bounds3 a, const Bounds3& b) { a.extend(b); return a; }

}  // namespace tessera
