// Scene's moving shapes (render/motion.h): instances built at finalize, rays intersected in each
// instance's object space at the ray's time.
#include "tessera/core/check.h"
#include "tessera/render/scene.h"

#include <cmath>

namespace tessera {

void Scene::build_motion(uint32_t first_prim) {
  num_static_prims_ = first_prim;
  motion_.clear();
  shape_motion_.assign(shapes.size(), 0);
  motion_bounds_ = Bounds3{};
  uint32_t next = first_prim;
  for (uint32_t si = 0; si < shapes.size(); ++si) {
    const Shape& s = *shapes[si];
    if (!s.motion) continue;
    // Emitters on moving shapes would need time-dependent light sampling; the loader refuses them.
    TESSERA_CHECK(s.light == nullptr);
    std::vector<std::array<Vec3, 3>> triangles;
    std::vector<SpherePrim> spheres;
    if (s.kind() == Shape::Kind::Mesh) {
      const auto& mesh = static_cast<const TriangleMeshShape&>(s).mesh();
      triangles.reserve(mesh.num_triangles());
      for (size_t t = 0; t < mesh.num_triangles(); ++t)
        triangles.push_back({mesh.positions[mesh.indices[3 * t]], mesh.positions[mesh.indices[3 * t + 1]],
                             mesh.positions[mesh.indices[3 * t + 2]]});
    } else {
      const auto& sphere = static_cast<const SphereShape&>(s);
      spheres.push_back({sphere.center(), sphere.radius()});
    }
    MotionInstance inst;
    inst.world_from_object = s.motion.get();
    inst.object_bvh = Bvh::build(std::move(triangles), std::move(spheres));
    inst.world_bounds = s.motion->motion_bounds(s.bounds(), shutter_open, shutter_close);
    inst.shape = si;
    inst.first_prim = next;
    shape_first_[si] = next;
    shape_motion_[si] = uint32_t(motion_.size());
    for (uint32_t p = 0; p < s.num_primitives(); ++p) prim_shape_.push_back(si);
    next += s.num_primitives();
    motion_bounds_.extend(inst.world_bounds);
    motion_.push_back(std::move(inst));
  }
}

bool Scene::motion_intersect(const Ray& ray, Hit& hit, bool found) const {
  Ray r = ray;
  if (found) r.tmax = std::fmin(r.tmax, hit.t);
  for (const MotionInstance& m : motion_) {
    if (!ray_hits_box(r, m.world_bounds)) continue;
    const Ray o = to_object_ray(r, m.world_from_object->at(r.time));
    Hit h;
    if (!m.object_bvh.intersect(o, h)) continue;
    hit = h;
    hit.prim += m.first_prim;
    r.tmax = h.t;
    found = true;
  }
  return found;
}

bool Scene::motion_occluded(const Ray& ray) const {
  for (const MotionInstance& m : motion_) {
    if (!ray_hits_box(ray, m.world_bounds)) continue;
    if (m.object_bvh.occluded(to_object_ray(ray, m.world_from_object->at(ray.time)))) return true;
  }
  return false;
}

void Scene::fill_moving(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const {
  const uint32_t shape_index = prim_shape_[hit.prim];
  const MotionInstance& m = motion_[shape_motion_[shape_index]];
  const Shape* shape = shapes[shape_index].get();
  const Transform xf = m.world_from_object->at(ray.time);
  const Ray o = to_object_ray(ray, xf);
  Hit local = hit;
  local.prim = hit.prim - m.first_prim;
  // A sphere's local primitive in its own BVH is 0 as well: the same index the shape expects.
  shape->fill_interaction(o, local, local.prim, si);
  // Object space -> world at the ray's time. Normals by the inverse transpose; the tangent frame
  // keeps its handedness relative to the normal.
  const Frame sh = si.shading;
  const bool right_handed = dot(cross(sh.n, sh.s), sh.t) >= 0.f;
  si.p_error = xf.apply_point_error(si.p, si.p_error);
  si.p = xf.apply_point(si.p);
  si.ng = normalize(xf.apply_normal(si.ng));
  Frame f;
  f.n = normalize(xf.apply_normal(sh.n));
  Vec3 s = xf.apply_vector(sh.s);
  s = s - f.n * dot(f.n, s);
  float ls = length(s);
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
