// Small scenes built in code for the integrator and renderer tests.
#pragma once

#include "tessera/bsdf/diffuse.h"
#include "tessera/core/transform.h"
#include "tessera/light/area.h"
#include "tessera/light/point.h"
#include "tessera/render/film.h"
#include "tessera/render/renderer.h"
#include "tessera/render/scene.h"

#include <cmath>
#include <memory>
#include <optional>

namespace tessera::test {

inline const Bsdf* add_diffuse(Scene& scene, Rgb albedo) {
  auto bsdf = make_diffuse_bsdf(std::make_shared<ConstantTexture>(albedo));
  scene.bsdfs.push_back(bsdf);
  return bsdf.get();
}

inline Shape* add_sphere(Scene& scene, Vec3 center, float radius, bool flip, const Bsdf* bsdf) {
  scene.shapes.push_back(std::make_unique<SphereShape>(center, radius, flip));
  scene.shapes.back()->bsdf = bsdf;
  return scene.shapes.back().get();
}

inline void add_area_light(Scene& scene, Shape& shape, Rgb radiance) {
  scene.lights.push_back(make_area_light(shape, radiance));
  shape.light = scene.lights.back().get();
}

/// Axis-aligned cube [-h, h]^3 as 12 triangles, normals pointing inwards (`inward`) or outwards.
inline std::shared_ptr<MeshData> cube_mesh(float h, bool inward) {
  auto m = std::make_shared<MeshData>();
  for (int i = 0; i < 8; ++i) m->positions.push_back({(i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h});
  // Outward-wound quads (a, b, c, d counter-clockwise seen from outside).
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    uint32_t tri[2][3] = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
    for (auto& t : tri) {
      if (inward) std::swap(t[1], t[2]);
      m->indices.insert(m->indices.end(), {t[0], t[1], t[2]});
    }
  }
  return m;
}

/// Pinhole camera at `origin` looking along +z (camera space = world space shifted).
inline void set_camera(Scene& scene, Vec3 origin, float fov_x, int width, int height) {
  scene.camera = make_perspective_camera(Transform::translate(origin), fov_x, width, height, 1e-3f, 1e4f);
  scene.film.width = width;
  scene.film.height = height;
}

/// Fixed seed, two threads and small tiles: what the render tests use (images are bit-identical for
/// any thread count and tile size anyway; these only keep the tests' work predictable).
inline RenderSettings render_settings(int spp, uint32_t seed = 1, int tile_size = 16) {
  RenderSettings s;
  s.spp = spp;
  s.seed = seed;
  s.threads = 2;
  s.tile_size = tile_size;
  return s;
}

/// The shape that covers pixel (x, y) entirely (its centre and four corners see it first), null
/// for pixels that see the environment only; nothing for pixels on silhouettes.
inline std::optional<const Shape*> cover(const Scene& scene, int x, int y) {
  std::optional<const Shape*> first;
  for (Vec2 off : {Vec2(0.5f, 0.5f), Vec2(0.01f, 0.01f), Vec2(0.99f, 0.01f), Vec2(0.01f, 0.99f), Vec2(0.99f, 0.99f)}) {
    SurfaceInteraction si;
    const Shape* s = scene.intersect(scene.camera->generate_ray(Vec2(x + off.x, y + off.y), {}), si) ? si.shape : nullptr;
    if (first && *first != s) return std::nullopt;
    first = s;
  }
  return first;
}

}  // namespace tessera::test
