// Watertightness: rays through shared edges and vertices of closed meshes never slip through.
#include "accel_test_support.h"
#include "tessera/accel/bvh.h"

#include <gtest/gtest.h>


namespace tessera {
namespace {

using test::Triangle;

/// Every vertex and edge point of the mesh, exactly as stored (vertices) or on the edge (points
/// interpolated in float: within rounding of the edge, which is what a watertight test must cope with).
std::vector<Vec3> edge_and_vertex_targets(const std::vector<Triangle>& tris, Pcg32& rng) {
  std::vector<Vec3> targets;
  for (const Triangle& t : tris) {
    for (int e = 0; e < 3; ++e) {
      const Vec3 a = t[e], b = t[(e + 1) % 3];
      targets.push_back(a);
      targets.push_back((a + b) * 0.5f);
      targets.push_back(a + (b - a) * rng.next_float());
    }
  }
  return targets;
}

/// From inside a closed mesh every ray must hit it.
void expect_no_escape(const Bvh& bvh, const std::vector<Vec3>& targets, Vec3 inside, float spread, Pcg32& rng) {
  size_t escaped = 0;
  for (const Vec3& target : targets) {
    const Vec3 o = inside + test::random_in_box(rng, -spread, spread);
    Hit hit;
    if (!bvh.intersect(Ray{o, target - o}, hit)) ++escaped;
    if (!bvh.occluded(Ray{o, target - o})) ++escaped;
  }
  EXPECT_EQ(escaped, 0u) << "of " << targets.size() << " rays";
}

/// From outside, rays aimed at a surface point that is not on the silhouette must hit there. `normals`
/// gives the outward normals of the faces through a target: the ray must come from the outer side
/// of each of them (not grazing), else it may touch the surface only at the target.
template <class Normals>
void expect_no_leak(const Bvh& bvh, const std::vector<Vec3>& targets, Normals normals, Pcg32& rng) {
  size_t leaked = 0, tried = 0;
  for (const Vec3& target : targets) {
    const std::vector<Vec3> ns = normals(target);
    for (int k = 0; k < 4; ++k) {
      Vec3 dir = test::random_unit(rng);
      if (dot(dir, ns[0]) < 0.f) dir = -dir;
      bool grazing = false;
      for (const Vec3& n : ns) grazing |= dot(dir, n) < 0.3f;
      if (grazing) continue;
      const Vec3 o = target + dir * (0.5f + 20.f * rng.next_float());
      ++tried;
      // The target is at t = 1. A ray slipping through the surface there would still hit the far
      // side, so a hit well beyond the target counts as a leak too. (Not just beyond: far from the
      // world origin the rounded direction moves the hit by ~ulp(|target|) / |target - o|.)
      Hit hit;
      if (!bvh.intersect(Ray{o, target - o}, hit) || hit.t > 1.01f) ++leaked;
    }
  }
  EXPECT_GT(tried, targets.size() / 10);
  EXPECT_EQ(leaked, 0u) << "of " << tried << " rays";
}

auto sphere_normals(Vec3 center) {
  return [center](Vec3 p) { return std::vector<Vec3>{normalize(p - center)}; };
}

/// Normals of the faces of the box [lo, hi] that contain p.
auto box_normals(Vec3 lo, Vec3 hi) {
  return [lo, hi](Vec3 p) {
    std::vector<Vec3> ns;
    for (int a = 0; a < 3; ++a) {
      Vec3 n(0.f);
      if (p[a] == lo[a]) n[a] = -1.f, ns.push_back(n);
      if (p[a] == hi[a]) n[a] = 1.f, ns.push_back(n);
    }
    return ns;
  };
}

TEST(Watertight, IcosphereFromInside) {
  Pcg32 rng(11);
  const Vec3 center(0.3f, -0.2f, 0.15f);
  const auto tris = test::icosphere(center, 1.7f, 3);
  ASSERT_EQ(tris.size(), 1280u);
  const Bvh bvh = Bvh::build(tris, {});
  expect_no_escape(bvh, edge_and_vertex_targets(tris, rng), center, 0.8f, rng);
}

TEST(Watertight, IcosphereFromOutside) {
  Pcg32 rng(12);
  const Vec3 center(0.3f, -0.2f, 0.15f);
  const auto tris = test::icosphere(center, 1.7f, 3);
  const Bvh bvh = Bvh::build(tris, {});
  expect_no_leak(bvh, edge_and_vertex_targets(tris, rng), sphere_normals(center), rng);
}

TEST(Watertight, FarAwayIcosphere) {
  // Far from the origin the vertices are coarse floats: shared edges must still be tight.
  Pcg32 rng(13);
  const Vec3 center(3000.5f, -1200.25f, 777.f);
  const auto tris = test::icosphere(center, 2.f, 2);
  const Bvh bvh = Bvh::build(tris, {});
  const auto targets = edge_and_vertex_targets(tris, rng);
  expect_no_escape(bvh, targets, center, 1.f, rng);
  expect_no_leak(bvh, targets, sphere_normals(center), rng);
}

TEST(Watertight, GridBoxFromInsideAndOutside) {
  Pcg32 rng(14);
  const Vec3 lo(-1.f, -0.5f, 0.25f), hi(1.5f, 0.75f, 2.f);
  const auto tris = test::grid_box(lo, hi, 4);
  ASSERT_EQ(tris.size(), 6u * 32u);
  const Bvh bvh = Bvh::build(tris, {});
  const Vec3 center = (lo + hi) * 0.5f;
  const auto targets = edge_and_vertex_targets(tris, rng);
  expect_no_escape(bvh, targets, center, 0.4f, rng);
  expect_no_leak(bvh, targets, box_normals(lo, hi), rng);
}

TEST(Watertight, AxisAlignedRaysThroughGridVertices) {
  // Rays parallel to an axis through the lattice points of a box's faces, from inside and outside:
  // exact zeros in the direction, exact edge and vertex hits.
  const Vec3 lo(0.f, 0.f, 0.f), hi(1.f, 1.f, 1.f);
  const int n = 4;
  const Bvh bvh = Bvh::build(test::grid_box(lo, hi, n), {});
  size_t missed = 0, total = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    for (int a = 1; a < n; ++a)
      for (int b = 1; b < n; ++b)
        for (float sign : {-1.f, 1.f}) {
          Vec3 p(0.f);
          p[u] = float(a) / float(n);
          p[w] = float(b) / float(n);
          Vec3 d(0.f);
          d[axis] = sign;
          // Outside: start 2 units before the face the ray enters.
          Vec3 outside = p;
          outside[axis] = sign > 0 ? -2.f : 3.f;
          Vec3 inside = p;
          inside[axis] = 0.5f;
          for (const Vec3& o : {outside, inside}) {
            Hit hit;
            ++total;
            if (!bvh.intersect(Ray{o, d}, hit)) ++missed;
            else EXPECT_FLOAT_EQ(o[axis] + sign * hit.t, sign > 0 ? (o[axis] < 0 ? 0.f : 1.f) : (o[axis] > 1 ? 1.f : 0.f));
          }
        }
  }
  EXPECT_EQ(missed, 0u) << "of " << total;
}

}  // namespace
}  // namespace tessera
