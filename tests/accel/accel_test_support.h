// Random scenes, brute-force references and closed test meshes for the accel tests.
#pragma once

#include "tessera/accel/bvh.h"
#include "tessera/core/hash.h"

#include <array>
#include <vector>

namespace tessera::test {

using Triangle = std::array<Vec3, 3>;

inline Vec3 random_in_box(Pcg32& rng, float lo, float hi) {
  return {lo + (hi - lo) * rng.next_float(), lo + (hi - lo) * rng.next_float(), lo + (hi - lo) * rng.next_float()};
}

inline Vec3 random_unit(Pcg32& rng) {
  for (;;) {
    Vec3 v = random_in_box(rng, -1.f, 1.f);
    float l2 = length_squared(v);
    if (l2 > 1e-4f && l2 <= 1.f) return v / std::sqrt(l2);
  }
}

/// Triangles of random size (mostly small, a few large) in [-10, 10]^3.
inline std::vector<Triangle> random_triangles(Pcg32& rng, size_t n) {
  std::vector<Triangle> tris(n);
  for (auto& t : tris) {
    const Vec3 c = random_in_box(rng, -10.f, 10.f);
    const float size = rng.next_float() < 0.05f ? 8.f : 0.05f + 1.5f * rng.next_float();
    for (auto& v : t) v = c + random_in_box(rng, -size, size);
  }
  return tris;
}

inline std::vector<SpherePrim> random_spheres(Pcg32& rng, size_t n) {
  std::vector<SpherePrim> s(n);
  for (auto& sp : s) sp = {random_in_box(rng, -10.f, 10.f), 0.05f + 1.5f * rng.next_float()};
  return s;
}

inline bool degenerate(const Triangle& t) {
  const Vec3 n = cross(t[1] - t[0], t[2] - t[0]);
  return n.x == 0.f && n.y == 0.f && n.z == 0.f;
}

/// Closest hit by testing every primitive (degenerate triangles excluded, as in the BVH).
inline bool brute_intersect(const std::vector<Triangle>& tris, const std::vector<SpherePrim>& spheres,
                            Ray ray, Hit& hit) {
  bool found = false;
  for (uint32_t i = 0; i < tris.size(); ++i) {
    float t, b1, b2;
    if (!degenerate(tris[i]) && intersect_triangle(ray, tris[i][0], tris[i][1], tris[i][2], t, b1, b2)) {
      ray.tmax = t;
      hit = {t, i, b1, b2};
      found = true;
    }
  }
  for (uint32_t i = 0; i < spheres.size(); ++i) {
    float t;
    if (spheres[i].radius > 0.f && intersect_sphere(ray, spheres[i].center, spheres[i].radius, t)) {
      ray.tmax = t;
      hit = {t, uint32_t(tris.size()) + i, 0.f, 0.f};
      found = true;
    }
  }
  return found;
}

/// Icosphere: an icosahedron subdivided `levels` times, vertices pushed to the sphere. Shared
/// vertices are bit-identical between the triangles that use them.
std::vector<Triangle> icosphere(Vec3 center, float radius, int levels);
/// Axis-aligned box [lo, hi] whose faces are n x n grids of quads, two triangles each.
std::vector<Triangle> grid_box(Vec3 lo, Vec3 hi, int n);

}  // namespace tessera::test
