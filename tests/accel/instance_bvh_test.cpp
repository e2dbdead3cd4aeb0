// The two-level BVH against brute force through every instance: rotated, non-uniformly scaled,
// mirrored and moving placements of two shared object-space BVHs.
#include "accel_test_support.h"
#include "tessera/accel/instance_bvh.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

using test::Triangle;

struct Group {
  std::vector<Triangle> tris;
  std::vector<SpherePrim> spheres;
  Bvh bvh;
};

Transform random_placement(Pcg32& rng, int kind) {
  const Vec3 axis = test::random_unit(rng);
  const float angle = 360.f * rng.next_float();
  Vec3 scale(0.2f + rng.next_float(), 0.2f + rng.next_float(), 0.2f + rng.next_float());
  if (kind % 3 == 1) scale = Vec3(0.5f);    // uniform
  if (kind % 3 == 2) scale.y = -scale.y;    // mirroring
  return Transform::translate(test::random_in_box(rng, -30.f, 30.f)) * Transform::rotate(axis, angle) *
         Transform::scale(scale);
}

/// The object-space ray an instance leaf traces (the same float map), so brute force and the
/// two-level BVH run the same triangle kernel on the same inputs.
Ray object_ray(const BvhInstance& in, const Ray& ray) {
  if (in.motion) return to_object_ray(ray, in.motion->at(ray.time));
  const Affine3 m = Affine3::from(in.world_from_object.inverse());
  Ray o = ray;
  o.o = m.point(ray.o);
  o.d = m.vector(ray.d);
  return o;
}

TEST(InstanceBvh, MatchesBruteForceThroughEveryInstance) {
  Pcg32 rng(11);
  std::vector<Group> groups(2);
  groups[0].tris = test::random_triangles(rng, 300);
  groups[0].spheres = test::random_spheres(rng, 10);
  groups[1].tris = test::random_triangles(rng, 120);
  for (Group& g : groups) g.bvh = Bvh::build(g.tris, g.spheres);

  AnimatedTransform moving({{0.f, Transform::translate(Vec3(-20.f, 0.f, 0.f))},
                            {1.f, Transform::translate(Vec3(20.f, 5.f, 0.f)) * Transform::rotate(Vec3(0, 0, 1), 90.f)}});
  std::vector<BvhInstance> instances;
  for (int i = 0; i < 40; ++i) {
    BvhInstance in;
    const Group& g = groups[size_t(i % 2)];
    in.bvh = &g.bvh;
    in.world_from_object = random_placement(rng, i);
    in.world_bounds = in.world_from_object.apply(g.bvh.bounds());
    if (i == 7) {
      in.motion = &moving;
      in.world_bounds = moving.motion_bounds(g.bvh.bounds(), 0.f, 1.f);
    }
    instances.push_back(in);
  }
  const InstanceBvh top = InstanceBvh::build(instances);
  ASSERT_EQ(top.size(), instances.size());

  size_t hits = 0, moving_hits = 0, mirrored_hits = 0;
  for (int i = 0; i < 4000; ++i) {
    Ray ray;
    ray.o = test::random_in_box(rng, -45.f, 45.f);
    ray.d = test::random_unit(rng) * (i % 3 == 0 ? 2.5f : 1.f);
    ray.time = rng.next_float();
    if (i % 5 == 2) ray.tmax = 30.f * rng.next_float();
    Hit expected;
    bool e = false;
    for (uint32_t k = 0; k < instances.size(); ++k) {
      const Group& g = groups[k % 2];
      Ray o = object_ray(instances[k], ray);
      o.tmax = e ? expected.t : ray.tmax;
      Hit h;
      if (!test::brute_intersect(g.tris, g.spheres, o, h)) continue;
      expected = h;
      expected.inst = k;
      e = true;
    }
    Hit got;
    const bool g = top.intersect(ray, got);
    ASSERT_EQ(e, g) << "ray " << i;
    EXPECT_EQ(top.occluded(ray), e) << "ray " << i;
    if (!e) continue;
    ++hits;
    moving_hits += got.inst == 7 ? 1 : 0;
    mirrored_hits += got.inst % 3 == 2 ? 1 : 0;
    ASSERT_EQ(expected.t, got.t) << "ray " << i;
    if (expected.inst == got.inst && expected.prim == got.prim) {
      EXPECT_EQ(expected.b1, got.b1);
      EXPECT_EQ(expected.b2, got.b2);
    }
  }
  // The comparison must exercise hits, through moving and mirrored instances too.
  EXPECT_GT(hits, 400u);
  EXPECT_GT(moving_hits, 5u);
  EXPECT_GT(mirrored_hits, 50u);
}

TEST(InstanceBvh, EmptyAndDegenerateInstancesNeverHit) {
  const InstanceBvh none = InstanceBvh::build({});
  Hit hit;
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(none.intersect(Ray{Vec3(0.f), Vec3(0, 0, 1)}, hit));
  const Bvh empty = Bvh::build({}, {});
  BvhInstance in;
  in.bvh = &empty;
  in.world_bounds = empty.bounds();
  EXPECT_TRUE(InstanceBvh::build({in}).empty());
}

TEST(InstanceBvh, SharedBvhCostsOnlyItsTopLevel) {
  Pcg32 rng(3);
  const Bvh bvh = Bvh::build(test::random_triangles(rng, 2000), {});
  std::vector<BvhInstance> instances(1000);
  for (auto& in : instances) {
    in.bvh = &bvh;
    in.world_from_object = random_placement(rng, 0);
    in.world_bounds = in.world_from_object.apply(bvh.bounds());
  }
  const InstanceBvh top = InstanceBvh::build(instances);
  // 2 million instanced triangles: the top level is a small fraction of one flattened copy.
  EXPECT_LT(top.bytes(), 200u * instances.size());
  EXPECT_LT(top.bytes(), bvh.stats().bytes);
}

}  // namespace
}  // namespace tessera
