#include "tessera/render/scene.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <chrono>

namespace tessera {

void Scene::finalize() {
  std::vector<std::array<Vec3, 3>> triangles;
  std::vector<SpherePrim> spheres;
  size_t tri_count = 0, sphere_count = 0;
  for (const auto& s : shapes) {
    if (s->kind() == Shape::Kind::Mesh) tri_count += s->num_primitives();
    else sphere_count += 1;
  }
  triangles.reserve(tri_count);
  spheres.reserve(sphere_count);

  // Global numbering: all mesh triangles first (shape order), then spheres (shape order), as the
  // BVH expects. prim_shape_ maps back; shape_first_ gives each shape's first global index.
  prim_shape_.assign(tri_count + sphere_count, 0);
  shape_first_.assign(shapes.size(), 0);
  uint32_t next_tri = 0, next_sphere = uint32_t(tri_count);
  for (uint32_t si = 0; si < shapes.size(); ++si) {
    const Shape& s = *shapes[si];
    if (s.kind() == Shape::Kind::Mesh) {
      const auto& mesh = static_cast<const TriangleMeshShape&>(s).mesh();
      shape_first_[si] = next_tri;
      for (size_t t = 0; t < mesh.num_triangles(); ++t) {
        triangles.push_back({mesh.positions[mesh.indices[3 * t]], mesh.positions[mesh.indices[3 * t + 1]],
                             mesh.positions[mesh.indices[3 * t + 2]]});
        prim_shape_[next_tri++] = si;
      }
    } else {
      const auto& sphere = static_cast<const SphereShape&>(s);
      shape_first_[si] = next_sphere;
      spheres.push_back({sphere.center(), sphere.radius()});
      prim_shape_[next_sphere++] = si;
    }
  }
  num_triangles_ = tri_count;
  auto t0 = std::chrono::steady_clock::now();
  accel_ = Bvh::build(std::move(triangles), std::move(spheres));
  bvh_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  Bounds3 b = accel_.bounds();
  if (b.empty()) b.extend(Vec3(0.f));
  infinite_lights_.clear();
  std::vector<float> power;
  power.reserve(lights.size());
  for (auto& l : lights) {
    l->scene_index = uint32_t(&l - lights.data());
    l->preprocess(b);
    if (l->is_infinite()) infinite_lights_.push_back(l.get());
    power.push_back(std::max(l->power(), 0.f));
  }
  light_distr_ = Distribution1D(power);
}

bool Scene::intersect(const Ray& ray, SurfaceInteraction& si) const {
  Hit hit;
  if (!accel_.intersect(ray, hit)) return false;
  TESSERA_DCHECK(hit.prim < prim_shape_.size());
  uint32_t shape_index = prim_shape_[hit.prim];
  const Shape* shape = shapes[shape_index].get();
  shape->fill_interaction(ray, hit, hit.prim - shape_first_[shape_index], si);
  si.shape = shape;
  return true;
}

const Light* Scene::sample_light(float u, float& pmf) const {
  if (lights.empty()) {
    pmf = 0.f;
    return nullptr;
  }
  uint32_t i = light_distr_.sample_discrete(u, &pmf);
  return lights[i].get();
}

float Scene::light_pmf(const Light* light) const {
  if (!light || light->scene_index >= lights.size() || lights[light->scene_index].get() != light) return 0.f;
  return light_distr_.pmf(light->scene_index);
}

}  // namespace tessera
