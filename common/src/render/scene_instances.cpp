// Scene's placed geometry (render/instance.h): a BVH per shapegroup and per moving shape, the
// placements, the top level over them, and completing a hit found through an instance.
#include "tessera/core/check.h"
#include "tessera/render/scene.h"

#include <cmath>

namespace tessera {

namespace {

/// The object-space primitives of `members` in the order Bvh numbers them (triangles, then spheres).
void gather_primitives(const std::vector<std::unique_ptr<Shape>>& shapes, const std::vector<uint32_t>& members,
                       std::vector<std::array<Vec3, 3>>& triangles, std::vector<SpherePrim>& spheres,
                       std::vector<uint32_t>& prim_shape, std::vector<uint32_t>& shape_first) {
  for (uint32_t si : members) {
    const Shape& s = *shapes[si];
    if (s.kind() != Shape::Kind::Mesh) continue;
    const auto& mesh = static_cast<const TriangleMeshShape&>(s).mesh();
    shape_first[si] = uint32_t(triangles.size());
    for (size_t t = 0; t < mesh.num_triangles(); ++t)
      triangles.push_back({mesh.positions[mesh.indices[3 * t]], mesh.positions[mesh.indices[3 * t + 1]],
                           mesh.positions[mesh.indices[3 * t + 2]]});
    prim_shape.insert(prim_shape.end(), mesh.num_triangles(), si);
  }
  for (uint32_t si : members) {
    const Shape& s = *shapes[si];
    if (s.kind() != Shape::Kind::Sphere) continue;
    const auto& sphere = static_cast<const SphereShape&>(s);
    shape_first[si] = uint32_t(triangles.size() + spheres.size());
    spheres.push_back({sphere.center(), sphere.radius()});
    prim_shape.push_back(si);
  }
}

}  // namespace

void Scene::build_instances() {
  // Groups: the shapegroups (numbered by Shape::group), then one per moving shape in shape order.
  uint32_t num_shapegroups = 0;
  for (const auto& s : shapes)
    if (s->group != Shape::kNoGroup) num_shapegroups = std::max(num_shapegroups, s->group + 1);
  for (const ShapeInstance& in : instances) num_shapegroups = std::max(num_shapegroups, in.group + 1);
  std::vector<std::vector<uint32_t>> members(num_shapegroups);
  for (uint32_t si = 0; si < shapes.size(); ++si) {
    const Shape& s = *shapes[si];
    // Emitters on placed shapes would need instanced or time-dependent light sampling; the loader
    // refuses them.
    if (s.is_placed()) TESSERA_CHECK(s.light == nullptr);
    if (s.group != Shape::kNoGroup) members[s.group].push_back(si);
    if (s.motion) members.push_back({si});
  }

  const uint64_t world_triangles = num_triangles_;
  groups_.assign(members.size(), {});
  std::vector<uint64_t> group_triangles(members.size(), 0);
  for (size_t g = 0; g < members.size(); ++g) {
    std::vector<std::array<Vec3, 3>> triangles;
    std::vector<SpherePrim> spheres;
    gather_primitives(shapes, members[g], triangles, spheres, groups_[g].prim_shape, shape_first_);
    group_triangles[g] = triangles.size();
    num_triangles_ += triangles.size();
    groups_[g].bvh = Bvh::build(std::move(triangles), std::move(spheres));
  }

  // Placements: the instances first (Hit::inst of a shapegroup's instance is its index in
  // `instances`), then the moving shapes, in the order of their groups.
  placements_.clear();
  for (const ShapeInstance& in : instances) {
    if (in.world_from_object.is_static()) placements_.push_back({in.group, in.world_from_object.at(shutter_open)});
    else placements_.push_back({in.group, Transform(), &in.world_from_object});
  }
  uint32_t moving_group = num_shapegroups;
  for (const auto& s : shapes)
    if (s->motion) placements_.push_back({moving_group++, Transform(), s->motion.get()});

  has_motion_ = false;
  num_instanced_triangles_ = world_triangles;  // a group's triangles count once per placement
  std::vector<BvhInstance> top;
  top.reserve(placements_.size());
  for (Placement& p : placements_) {
    const Bounds3 b = groups_[p.group].bvh.bounds();
    p.world_bounds = p.motion ? p.motion->motion_bounds(b, shutter_open, shutter_close) : p.world_from_object.apply(b);
    has_motion_ = has_motion_ || p.motion != nullptr;
    num_instanced_triangles_ += group_triangles[p.group];
    top.push_back({&groups_[p.group].bvh, p.world_from_object, p.motion, p.world_bounds});
  }
  top_ = InstanceBvh::build(top);
}

void Scene::fill_placed(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const {
  const Placement& p = placements_[hit.inst];
  const GroupAccel& g = groups_[p.group];
  TESSERA_DCHECK(hit.prim < g.prim_shape.size());
  const uint32_t shape_index = g.prim_shape[hit.prim];
  const Shape* shape = shapes[shape_index].get();
  const Transform xf = p.motion ? p.motion->at(ray.time) : p.world_from_object;
  const Ray o = to_object_ray(ray, xf);
  Hit local = hit;
  local.prim = hit.prim - shape_first_[shape_index];
  shape->fill_interaction(o, local, local.prim, si);
  // Object space -> world. Normals by the inverse transpose; the tangent frame keeps its
  // handedness relative to the normal.
  const Frame sh = si.shading;
  const bool right_handed = dot(cross(sh.n, sh.s), sh.t) >= 0.f;
  si.p_error = xf.apply_point_error(si.p, si.p_error);
  si.p = xf.apply_point(si.p);
  si.ng = normalize(xf.apply_normal(si.ng));
  Frame f;
  f.n = normalize(xf.apply_normal(sh.n));
  Vec3 s = xf.apply_vector(sh.s);
  s = s - f.n * dot(f.n, s);
  const float ls = length(s);
  if (ls > 1e-12f && std::isfinite(ls)) {
    f.s = s / ls;
    f.t = right_handed ? cross(f.n, f.s) : cross(f.s, f.n);
  } else {
    f = Frame(f.n);
  }
  si.shading = f;
  si.dpdu = xf.apply_vector(si.dpdu);
  si.dpdv = xf.apply_vector(si.dpdv);
  si.wo = normalize(-ray.d);
  si.t = hit.t;
  si.shape = shape;
}

}  // namespace tessera
