#include "tessera/render/scene.h"

#include "tessera/core/check.h"
#include "tessera/core/hash.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <unordered_set>

namespace tessera {

void Scene::finalize() {
  std::vector<std::array<Vec3, 3>> triangles;
  std::vector<SpherePrim> spheres;
  size_t tri_count = 0, sphere_count = 0;
  for (const auto& s : shapes) {
    if (s->is_placed()) continue;  // build_instances()
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
    if (s.is_placed()) continue;
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
  has_media_ = camera_medium != nullptr ||
               std::any_of(shapes.begin(), shapes.end(), [](const auto& s) { return s->medium_interface; });
  has_masks_ = std::any_of(shapes.begin(), shapes.end(),
                           [](const auto& s) { return s->bsdf && s->bsdf->has_opacity(); });
  flag_see_through();
  auto t0 = std::chrono::steady_clock::now();
  accel_ = Bvh::build(std::move(triangles), std::move(spheres));
  build_instances();
  bvh_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  Bounds3 b = bounds();
  if (b.empty()) b.extend(Vec3(0.f));
  infinite_lights_.clear();
  for (auto& l : lights) {
    l->scene_index = uint32_t(&l - lights.data());
    l->preprocess(b);
    if (l->is_infinite()) infinite_lights_.push_back(l.get());
  }
  light_sampler_.build(lights, shapes, integrator.light_selection);
  const bool bidirectional = is_bidirectional(integrator.type) || uses_light_vertex_passes(integrator.type);
  const bool distant = std::any_of(lights.begin(), lights.end(), [](const auto& l) { return l->is_distant(); });
  emission_portal_ = bidirectional && distant ? find_emission_portal(*this) : EmissionPortal{};
}

void Scene::fill(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const {
  if (hit.inst != Hit::kNoInstance) return fill_placed(ray, hit, si);
  TESSERA_DCHECK(hit.prim < prim_shape_.size());
  uint32_t shape_index = prim_shape_[hit.prim];
  const Shape* shape = shapes[shape_index].get();
  shape->fill_interaction(ray, hit, hit.prim - shape_first_[shape_index], si);
  si.shape = shape;
}

namespace {

// Beyond this many masked surfaces along one ray the next one counts as opaque: bounds the work
// of a ray through a dense stack of cut-outs (a hedge seen end-on) at a negligible bias.
constexpr int kMaxMaskCrossings = 64;

float masked_opacity(const SurfaceInteraction& si) {
  const Bsdf* bsdf = si.bsdf();
  return bsdf && bsdf->has_opacity() ? bsdf->opacity(si) : 1.f;
}

bool is_null_surface(const SurfaceInteraction& si) {
  const Bsdf* bsdf = si.bsdf();
  return bsdf && bsdf->is_null();
}

// A uniform number from the ray itself (as pbrt-v4's alpha test): deterministic, independent of
// the sampler's dimension layout, and different for every ray that differs in a bit.
float alpha_test_u(const Ray& r) {
  auto b = [](float f) { return uint64_t(std::bit_cast<uint32_t>(f)); };
  uint64_t h = hash_values(b(r.o.x) | b(r.o.y) << 32, b(r.o.z) | b(r.d.x) << 32, b(r.d.y) | b(r.d.z) << 32);
  return bits_to_unit_float(uint32_t(h >> 32));
}

// The continuation of `r` past a surface hit at parameter t: same direction and parametrisation,
// origin offset past the surface, the remaining range kept.
Ray continue_ray(const Ray& r, const SurfaceInteraction& si, float t) {
  Ray next = r;
  next.o = offset_ray_origin(si.p, si.p_error, si.ng, r.d);
  next.tmax = r.tmax - t;
  return next;
}

}  // namespace

bool Scene::intersect(const Ray& ray, SurfaceInteraction& si, bool stop_at_null) const {
  Hit hit;
  if (!closest_hit(ray, hit)) return false;
  fill(ray, hit, si);
  if (!has_masks_) return true;
  Ray r = ray;
  float t_before = 0.f;  // parameter of r.o along the original ray
  for (int crossing = 0; crossing < kMaxMaskCrossings; ++crossing) {
    float opacity = masked_opacity(si);
    if (opacity >= 1.f || alpha_test_u(r) < opacity) break;
    if (stop_at_null && is_null_surface(si)) break;
    t_before += si.t;
    r = continue_ray(r, si, si.t);
    if (!(r.tmax > 0.f) || !closest_hit(r, hit)) return false;
    fill(r, hit, si);
  }
  si.t += t_before;
  return true;
}

void Scene::flag_see_through() {
  see_through_.clear();
  if (!has_masks_) return;
  std::vector<uint64_t> bits((prim_shape_.size() + 63) / 64, 0);
  for (uint32_t si = 0; si < shapes.size(); ++si) {
    const Shape& s = *shapes[si];
    if (!s.bsdf || !s.bsdf->has_opacity()) continue;
    // A sphere is crossed twice and a placed shape is not in the world BVH: the loop handles those.
    if (s.is_placed() || s.kind() != Shape::Kind::Mesh) return;
    for (uint32_t p = shape_first_[si], end = p + uint32_t(s.num_primitives()); p < end; ++p)
      bits[p >> 6] |= uint64_t(1) << (p & 63);
  }
  see_through_ = std::move(bits);
}

/// What a shadow ray crossed so far in one any-hit query through cut-outs (HitFilter's ctx).
struct Scene::MaskCrossings {
  const Scene* scene;
  float tr = 1.f;
  int crossings = 0;
  static bool occludes(void* ctx, const Ray& ray, const Hit& hit) {
    auto& c = *static_cast<MaskCrossings*>(ctx);
    if (++c.crossings > kMaxMaskCrossings) return true;
    SurfaceInteraction si;
    c.scene->fill(ray, hit, si);
    c.tr *= 1.f - masked_opacity(si);
    return !(c.tr > 0.f);
  }
};

float Scene::transmittance(const Ray& ray) const {
  if (!has_masks_) return occluded(ray) ? 0.f : 1.f;
  if (!see_through_.empty()) {
    // Every primitive on the segment is offered once, so the product over the cut-outs is the
    // one the loop below finds, without a closest-hit query (and a fill) per surface.
    MaskCrossings c{this};
    if (accel_.occluded(ray, HitFilter{see_through_.data(), &MaskCrossings::occludes, &c})) return 0.f;
    if (!top_.empty() && top_.occluded(ray)) return 0.f;
    return c.tr;
  }
  Ray r = ray;
  float tr = 1.f;
  SurfaceInteraction si;
  for (int crossing = 0;; ++crossing) {
    Hit hit;
    if (!closest_hit(r, hit)) return tr;
    if (crossing == kMaxMaskCrossings) return 0.f;  // as intersect(): that one counts as opaque
    fill(r, hit, si);
    tr *= 1.f - masked_opacity(si);
    if (!(tr > 0.f)) return 0.f;
    r = continue_ray(r, si, si.t);
    if (!(r.tmax > 0.f)) return tr;
  }
}

Rgb Scene::transmittance(const Ray& ray, const Medium* medium) const {
  if (!has_media_) return Rgb(transmittance(ray));
  Ray r = ray;
  Rgb tr(1.f);
  SurfaceInteraction si;
  for (int crossing = 0;; ++crossing) {
    Hit hit;
    const bool found = closest_hit(r, hit);
    if (medium) tr *= medium->transmittance(r, found ? hit.t : r.tmax);
    if (!found) return tr;
    if (crossing == kMaxMaskCrossings) return {};
    fill(r, hit, si);
    tr *= 1.f - masked_opacity(si);
    if (tr.is_black()) return {};
    if (is_null_surface(si)) medium = medium_after(si, r.d, medium);
    r = continue_ray(r, si, si.t);
    if (!(r.tmax > 0.f)) return tr;
  }
}

size_t Scene::accel_bytes() const {
  size_t bytes = accel_.stats().bytes + top_.bytes() + prim_shape_.size() * sizeof(uint32_t);
  for (const GroupAccel& g : groups_) bytes += g.bvh.stats().bytes + g.prim_shape.size() * sizeof(uint32_t);
  return bytes;
}

SceneMemory Scene::memory() const {
  SceneMemory m;
  m.accel = accel_bytes();
  std::unordered_set<const void*> counted;
  for (const auto& shape : shapes) {
    if (shape->kind() != Shape::Kind::Mesh) continue;
    const MeshData& mesh = static_cast<const TriangleMeshShape&>(*shape).mesh();
    if (!counted.insert(&mesh).second) continue;
    m.meshes += mesh.positions.size() * sizeof(Vec3) + mesh.normals.size() * sizeof(Vec3) +
                mesh.uvs.size() * sizeof(Vec2) + mesh.indices.size() * sizeof(uint32_t);
  }
  for (const auto& t : textures) m.images += t->memory_bytes(counted);
  for (const auto& l : lights) m.images += l->memory_bytes();
  return m;
}

const Light* Scene::sample_light(const LightSampleContext& ctx, float u, float& pmf) const {
  return light_sampler_.sample(ctx, u, pmf);
}

float Scene::light_pmf(const LightSampleContext& ctx, const Light* light) const {
  return light_sampler_.pmf(ctx, light);
}

}  // namespace tessera
