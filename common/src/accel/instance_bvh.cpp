// InstanceBvh: the top level over instance boxes (the binned SAH builder of Bvh, one instance per
// leaf slot) and its traversal, which traces each instance entered in its object-space Bvh.
#include "tessera/accel/instance_bvh.h"

#include "accel/bvh_binary.h"
#include "accel/wide_traversal.h"

#include <algorithm>
#include <limits>

namespace tessera {
using namespace accel_detail;

Affine3 Affine3::from(const Transform& t) {
  Affine3 a;
  const auto& m = t.matrix().m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.m[r][c] = float(m[r][c]);
  return a;
}

Ray to_object_ray(const Ray& r, const Transform& world_from_object) {
  Ray o = r;
  const Transform inv = world_from_object.inverse();
  o.o = inv.apply_point(r.o);
  o.d = inv.apply_vector(r.d);
  return o;
}

InstanceBvh InstanceBvh::build(const std::vector<BvhInstance>& instances) {
  TESSERA_CHECK(instances.size() < size_t(bvh_ref::kMaxFirst));
  HugeVector<PrimRef> refs;
  for (uint32_t i = 0; i < instances.size(); ++i) {
    const BvhInstance& in = instances[i];
    const Bounds3& b = in.world_bounds;
    if (!in.bvh || b.empty() || !is_finite(b.lo) || !is_finite(b.hi)) continue;
    // A little slack: the box's corners were rounded to float, and rays reach object space through
    // a float matrix, so a hit at the very edge of the geometry must not be culled by its box.
    const float pad = 64.f * std::numeric_limits<float>::epsilon() *
                      std::max(max_component(vabs(b.lo)), max_component(vabs(b.hi)));
    PrimRef r{};
    r.lo = b.lo - Vec3(pad);
    r.hi = b.hi + Vec3(pad);
    r.prim = i;
    refs.push_back(r);
  }
  InstanceBvh top;
  const HugeVector<BinaryNode> binary = build_binary(refs, 1);
  const LeafSlots slots = assign_slots(binary, 1);
  top.leaves_.reserve(refs.size());
  for (const PrimRef& r : refs) {  // build_binary left them in leaf order
    const BvhInstance& in = instances[r.prim];
    top.leaves_.push_back({in.bvh, in.motion, Affine3::from(in.world_from_object.inverse()), r.prim});
  }
  top.nodes_ = collapse_to_wide(binary, slots.refs);
  top.bounds_ = binary.empty() ? Bounds3{} : binary[0].bounds;
  return top;
}

size_t InstanceBvh::bytes() const { return nodes_.size() * sizeof(BvhNode) + leaves_.size() * sizeof(Leaf); }

namespace {

/// Top-level leaves: runs of instances, each traced in its own object space.
template <bool kAnyHit>
struct InstanceLeaves {
  const InstanceBvh::Leaf* leaves;
  void prefetch(uint32_t ref) const { __builtin_prefetch(leaves + bvh_ref::leaf_first(ref)); }
  bool intersect(uint32_t ref, const Ray& ray, float& tmax, Hit& hit) const {
    const uint32_t first = bvh_ref::leaf_first(ref), end = first + bvh_ref::leaf_count(ref);
    bool found = false;
    for (uint32_t i = first; i < end; ++i) {
      const InstanceBvh::Leaf& leaf = leaves[i];
      Ray o = ray;
      if (leaf.motion) {
        o = to_object_ray(ray, leaf.motion->at(ray.time));
      } else {
        o.o = leaf.object_from_world.point(ray.o);
        o.d = leaf.object_from_world.vector(ray.d);
      }
      o.tmax = tmax;
      if constexpr (kAnyHit) {
        if (leaf.bvh->occluded(o)) return true;
      } else {
        Hit h;
        if (!leaf.bvh->intersect(o, h)) continue;
        hit = h;
        hit.inst = leaf.index;
        tmax = h.t;
        found = true;
      }
    }
    return found;
  }
};

}  // namespace

template <bool kAnyHit>
bool InstanceBvh::trace(const Ray& ray, Hit& hit) const {
  if (nodes_.empty()) return false;
  float tmax = ray.tmax;
  return traverse<kAnyHit>(nodes_.data(), InstanceLeaves<kAnyHit>{leaves_.data()}, ray, BoxRay::make(ray), tmax, hit);
}

bool InstanceBvh::intersect(const Ray& ray, Hit& hit) const { return trace<false>(ray, hit); }

bool InstanceBvh::occluded(const Ray& ray) const {
  Hit unused;
  return trace<true>(ray, unused);
}

}  // namespace tessera
