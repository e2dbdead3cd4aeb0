// Robust ray offsets: spawned rays never re-hit the surface they leave, near or far from the origin.
#include "accel_test_support.h"
#include "tessera/accel/bvh.h"
#include "tessera/core/frame.h"
#include "tessera/render/interaction.h"
#include "tessera/render/shape.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using test::Triangle;

/// A flat, randomly oriented grid of triangles around `center` (coplanar neighbours share edges).
std::vector<Triangle> tilted_grid(Vec3 center, float size, int n, Pcg32& rng, Vec3& normal) {
  normal = test::random_unit(rng);
  const Frame f(normal);
  std::vector<Triangle> tris;
  auto at = [&](int i, int j) {
    return center + f.s * (size * (float(i) / float(n) - 0.5f)) + f.t * (size * (float(j) / float(n) - 0.5f));
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      tris.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      tris.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return tris;
}

Vec3 geometric_normal(const Triangle& t) { return normalize(cross(t[1] - t[0], t[2] - t[0])); }

/// Hits the grid with random rays, then spawns rays from each hit point (computed from the
/// barycentrics, as a shape does) into both hemispheres: none may hit the grid again.
void check_no_self_hit(Vec3 center, float size, uint64_t seed) {
  Pcg32 rng(seed);
  Vec3 n;
  const auto tris = tilted_grid(center, size, 8, rng, n);
  const Bvh bvh = Bvh::build(tris, {});
  size_t hits = 0, self_hits = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vec3 side = rng.next_float() < 0.5f ? n : -n;
    const Vec3 target = center + test::random_in_box(rng, -0.4f * size, 0.4f * size);
    const Vec3 o = target + (side + test::random_unit(rng) * 0.9f) * size;
    Hit hit;
    if (!bvh.intersect(Ray{o, target - o}, hit)) continue;
    ++hits;
    const Triangle& t = tris[hit.prim];
    const float b0 = 1.f - hit.b1 - hit.b2;
    const Vec3 p = t[0] * b0 + t[1] * hit.b1 + t[2] * hit.b2;
    const Vec3 p_error = barycentric_point_error(t[0], t[1], t[2], b0, hit.b1, hit.b2);
    const Vec3 ng = geometric_normal(t);
    for (int k = 0; k < 4; ++k) {
      Vec3 d = test::random_unit(rng);
      if (k == 3) d = normalize(d - ng * dot(d, ng) + ng * (dot(d, ng) < 0 ? -1e-3f : 1e-3f));  // grazing
      Hit again;
      if (bvh.intersect(spawn_ray(p, p_error, ng, d), again)) ++self_hits;
      // The overload without a bound estimates it from |p|: as good on these small grids.
      if (bvh.intersect(spawn_ray(p, ng, d), again)) ++self_hits;
    }
  }
  EXPECT_GT(hits, 3000u);
  EXPECT_EQ(self_hits, 0u) << "of " << 8 * hits << " spawned rays";
}

TEST(Offset, NoSelfHitNearOrigin) { check_no_self_hit(Vec3(0.01f, -0.02f, 0.005f), 0.05f, 21); }
TEST(Offset, NoSelfHitUnitScale) { check_no_self_hit(Vec3(1.5f, -2.f, 0.7f), 2.f, 22); }
TEST(Offset, NoSelfHitFarFromOrigin) { check_no_self_hit(Vec3(1e4f, -3.5e3f, 8e3f), 5.f, 23); }
TEST(Offset, NoSelfHitVeryFarFromOrigin) { check_no_self_hit(Vec3(-2e5f, 1e5f, -7e4f), 50.f, 24); }

TEST(Offset, SphereSpawnedRaysLeaveTheSurface) {
  // Hit points reprojected onto the sphere (as a shape does); rays leaving outwards must not hit the
  // sphere again, rays going inwards must reach the far side, not the surface they start on.
  Pcg32 rng(26);
  for (const SpherePrim s : {SpherePrim{Vec3(0.1f, 0.2f, -0.3f), 1.f}, SpherePrim{Vec3(1e4f, -2e3f, 5e3f), 3.f},
                             SpherePrim{Vec3(0.f), 0.01f}}) {
    const Bvh bvh = Bvh::build({}, {s});
    size_t bad = 0, tried = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3 o = s.center + test::random_unit(rng) * (s.radius * 4.f);
      const Vec3 aim = s.center + test::random_in_box(rng, -0.5f * s.radius, 0.5f * s.radius);
      Hit hit;
      if (!bvh.intersect(Ray{o, normalize(aim - o)}, hit)) continue;
      const SphereShape shape(s.center, s.radius, false);
      Vec3 p_error;
      const Vec3 p = shape.reproject(o + normalize(aim - o) * hit.t, p_error);
      const Vec3 n = normalize(p - s.center);
      Vec3 d = test::random_unit(rng);
      ++tried;
      Hit again;
      const bool h = bvh.intersect(spawn_ray(p, p_error, n, d), again);
      if (dot(d, n) > 0.f ? h : (!h || again.t < 1e-3f * s.radius)) ++bad;
    }
    EXPECT_GT(tried, 1000u);
    EXPECT_EQ(bad, 0u) << "sphere at " << s.center.x << " radius " << s.radius;
  }
}

TEST(Offset, WithoutOffsetSelfHitsHappen) {
  // The check above must be able to fail: spawning from the raw hit point does re-hit, far away.
  Pcg32 rng(25);
  Vec3 n;
  const Vec3 center(1e4f, -3.5e3f, 8e3f);
  const auto tris = tilted_grid(center, 5.f, 8, rng, n);
  const Bvh bvh = Bvh::build(tris, {});
  size_t self_hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 target = center + test::random_in_box(rng, -2.f, 2.f);
    const Vec3 o = target + n * 5.f + test::random_unit(rng);
    Hit hit;
    if (!bvh.intersect(Ray{o, target - o}, hit)) continue;
    const Triangle& t = tris[hit.prim];
    const Vec3 p = t[0] * (1.f - hit.b1 - hit.b2) + t[1] * hit.b1 + t[2] * hit.b2;
    Vec3 d = test::random_unit(rng);
    if (dot(d, n) < 0) d = -d;
    Hit again;
    if (bvh.intersect(Ray{p, d}, again)) ++self_hits;
  }
  EXPECT_GT(self_hits, 20u);
}

TEST(Offset, MovesAlongNormalOnBothSidesOfZero) {
  // The offset is the error box projected on the normal, rounded away: every coordinate the normal
  // has a component along moves to the side w points to, by at least one float, and no further
  // than the projection plus that rounding; other coordinates stay.
  for (Vec3 p : {Vec3(0.f), Vec3(1e-3f, -1e-3f, 0.f), Vec3(10.f, -10.f, 1e4f), Vec3(-1e6f, 1e6f, 3.f)}) {
    const Vec3 err = estimated_point_error(p) + Vec3(1e-30f);
    for (Vec3 nrm : {Vec3(1, 0, 0), Vec3(0, -1, 0), normalize(Vec3(1, 1, -1))}) {
      for (float side : {1.f, -1.f}) {
        const Vec3 q = offset_ray_origin(p, err, nrm, nrm * side);
        const float d = dot(vabs(nrm), err);
        for (int a = 0; a < 3; ++a) {
          if (nrm[a] * side > 0.f) {
            EXPECT_GT(q[a], p[a]);
          } else if (nrm[a] * side < 0.f) {
            EXPECT_LT(q[a], p[a]);
          } else {
            EXPECT_EQ(q[a], p[a]);
          }
          const float ulp = std::nextafter(std::abs(p[a]) + d, kInfinity) - (std::abs(p[a]) + d);
          EXPECT_LE(std::abs(q[a] - p[a]), d * std::abs(nrm[a]) + 2.f * ulp);
        }
        EXPECT_GT(dot(q - p, nrm * side), 0.f);
      }
    }
  }
  // The offset follows the error bound, not the position: a tiny error gives a tiny offset far out.
  const Vec3 p(1e4f, 1e4f, 1e4f);
  const Vec3 q = offset_ray_origin(p, Vec3(0.f), Vec3(0, 0, 1), Vec3(0, 0, 1));
  EXPECT_EQ(q.x, p.x);
  EXPECT_EQ(q.z, p.z);  // no error, no offset
}

TEST(Offset, SpawnRayToStopsShortOfTarget) {
  // Two facing walls: a shadow ray between points on them is unoccluded; a blocker occludes it.
  const float far = 1e4f;
  std::vector<Triangle> tris = {
      {Vec3(far - 1, -1, 0), Vec3(far + 1, -1, 0), Vec3(far, 1, 0)},     // floor, normal +z
      {Vec3(far - 1, -1, 2), Vec3(far, 1, 2), Vec3(far + 1, -1, 2)}};  // ceiling, normal -z
  const Vec3 p(far, 0.f, 0.f), target(far, 0.f, 2.f);
  const Bvh walls = Bvh::build(tris, {});
  EXPECT_FALSE(walls.occluded(spawn_ray_to(p, Vec3(0, 0, 1), target)));
  EXPECT_FALSE(walls.occluded(spawn_ray_to(target, Vec3(0, 0, -1), p)));
  // The normal's orientation must not matter: the origin moves to the target's side.
  EXPECT_FALSE(walls.occluded(spawn_ray_to(p, Vec3(0, 0, -1), target)));
  tris.push_back({Vec3(far - 1, -1, 1), Vec3(far + 1, -1, 1), Vec3(far, 1, 1)});
  const Bvh blocked = Bvh::build(tris, {});
  EXPECT_TRUE(blocked.occluded(spawn_ray_to(p, Vec3(0, 0, 1), target)));
}

class StubShape final : public Shape {
 public:
  Kind kind() const override { return Kind::Mesh; }
  uint32_t num_primitives() const override { return 0; }
  Bounds3 bounds() const override { return {}; }
  float area() const override { return 0.f; }
  void sample_area(Vec2, Vec3&, Vec3&, float&) const override {}
  void fill_interaction(const Ray&, const Hit&, uint32_t, SurfaceInteraction&) const override {}
};

TEST(Offset, SurfaceInteractionForwardsShapeMaterials) {
  SurfaceInteraction si;
  EXPECT_EQ(si.bsdf(), nullptr);
  EXPECT_EQ(si.area_light(), nullptr);
  // Only the pointers matter here; they are never dereferenced.
  alignas(64) static char bsdf_storage[64], light_storage[64];
  StubShape shape;
  shape.bsdf = reinterpret_cast<const Bsdf*>(bsdf_storage);
  shape.light = reinterpret_cast<const Light*>(light_storage);
  si.shape = &shape;
  EXPECT_EQ(si.bsdf(), shape.bsdf);
  EXPECT_EQ(si.area_light(), shape.light);
}

}  // namespace
}  // namespace tessera
