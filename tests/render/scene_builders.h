// Small scenes built in code for the integrator and renderer tests.
#pragma once

#include "tessera/bsdf/diffuse.h"
#include "tessera/core/transform.h"
#include "tessera/light/area.h"
#include "tessera/light/point.h"
#include "tessera/render/film.h"
#include "tessera/sequence/renderer.h"
#include "tessera/render/scene.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

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

/// An open box (floor, back and left walls) under a dim sky, with every kind of light path the
/// path tracer's strategies treat differently: area lights of two sizes, a point light, a constant
/// sky, a perfect mirror, smooth plastic (a delta coat over a diffuse base), a rough conductor.
inline const char* kMixedScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="6"/></integrator>
  <sensor type="perspective"><float name="fov" value="55"/>
    <transform name="to_world"><lookat origin="0,1.2,4.5" target="0,0.6,0" up="0,1,0"/></transform>
    <sampler type="independent"><integer name="sample_count" value="4"/></sampler>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
      <rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="grey"><rgb name="reflectance" value="0.6"/></bsdf>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="-90"/></transform>
    <ref id="grey"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><translate z="-2"/></transform>
    <ref id="grey"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate y="1" angle="90"/>
    <translate x="-2"/></transform><bsdf type="diffuse"><rgb name="reflectance" value="0.7,0.2,0.2"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="-0.9" y="0.5" z="0"/><float name="radius" value="0.5"/>
    <bsdf type="conductor"/></shape>
  <shape type="sphere"><point name="center" x="0.4" y="0.45" z="0.4"/><float name="radius" value="0.45"/>
    <bsdf type="plastic"><rgb name="diffuse_reflectance" value="0.2,0.3,0.7"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="1.3" y="0.4" z="-0.8"/><float name="radius" value="0.4"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.15"/></bsdf></shape>
  <shape type="sphere"><point name="center" x="0.8" y="2.2" z="-0.5"/><float name="radius" value="0.25"/>
    <emitter type="area"><rgb name="radiance" value="12,10,8"/></emitter></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="90"/>
    <translate x="-0.8" y="2.5" z="0.2"/></transform>
    <emitter type="area"><rgb name="radiance" value="4,4,5"/></emitter></shape>
  <emitter type="point"><point name="position" x="-1.2" y="1.8" z="1.5"/><rgb name="intensity" value="3"/></emitter>
  <emitter type="constant"><rgb name="radiance" value="0.3,0.35,0.4"/></emitter>
</scene>)";

/// A scene file rendered by `integrator` with the depths its own integrator has (an integrator
/// given on the command line ignores the file's other parameters): one scene, several methods.
inline std::unique_ptr<Scene> load_as(const std::string& xml, const std::string& integrator) {
  LoadOptions o;
  o.integrator = integrator;
  LoadResult r = load_scene(parse_scene_string(xml, "test_scene.xml"), o);
  const LoadResult own = load_scene(parse_scene_string(xml, "test_scene.xml"), LoadOptions{});
  r.scene->integrator.max_depth = own.scene->integrator.max_depth;
  r.scene->integrator.rr_depth = own.scene->integrator.rr_depth;
  return std::move(r.scene);
}

// A room lit only by a point light inside a glass ball: every light path leaves through the glass,
// which neither next-event estimation nor a BSDF-sampled ray can cross to a point. The path tracer
// renders it black; bdpt, ptracer and sppm light it (light subpaths through the glass). EXTRA: a
// placeholder for more of the scene.
inline const char* kCagedLightScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="8"/></integrator>
  <sensor type="perspective"><float name="fov" value="70"/>
    <transform name="to_world"><lookat origin="0,1,1.4" target="0,0.8,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="16"/><integer name="height" value="12"/></film>
  </sensor>
  <shape type="cube"><transform name="to_world"><scale x="1.5" y="1" z="1.5"/><translate y="1"/></transform>
    <boolean name="flip_normals" value="true"/><bsdf type="diffuse"/></shape>
  <shape type="sphere"><point name="center" x="0" y="1.2" z="-0.5"/><float name="radius" value="0.3"/><bsdf type="dielectric"/></shape>
  <emitter type="point"><point name="position" x="0" y="1.2" z="-0.5"/><rgb name="intensity" value="3"/></emitter>
  EXTRA
</scene>)";

inline std::unique_ptr<Scene> mixed_scene() {
  LoadResult r = load_scene(parse_scene_string(kMixedScene, "mixed_scene.xml"), LoadOptions{});
  return std::move(r.scene);
}

// Fog around a glass ball filled with a denser medium, a rough metal ball and a diffuse floor,
// lit by a sphere light and a dim sky.
inline const char* kFogScene = R"(<scene version="3.0.0">
  <integrator type="volpath"><integer name="max_depth" value="10"/></integrator>
  <sensor type="perspective"><float name="fov" value="45"/>
    <transform name="to_world"><lookat origin="0,1,5" target="0,0.7,0" up="0,1,0"/></transform>
    <medium type="homogeneous" name="medium" id="fog"><float name="sigma_t" value="0.1"/>
      <rgb name="albedo" value="0.8,0.8,0.9"/></medium>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
      <rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><scale value="4"/></transform>
    <bsdf type="diffuse"/><ref name="exterior" id="fog"/></shape>
  <shape type="sphere"><point name="center" value="-0.7,0.7,0"/><float name="radius" value="0.6"/>
    <bsdf type="dielectric"/>
    <medium type="homogeneous" name="interior"><float name="sigma_t" value="1.5"/>
      <rgb name="albedo" value="0.9,0.6,0.4"/></medium>
    <ref name="exterior" id="fog"/></shape>
  <shape type="sphere"><point name="center" value="0.8,0.5,0.3"/><float name="radius" value="0.5"/>
    <bsdf type="roughconductor"><float name="alpha" value="0.25"/></bsdf><ref name="exterior" id="fog"/></shape>
  <shape type="sphere"><point name="center" value="0.5,2.6,1"/><float name="radius" value="0.6"/>
    <emitter type="area"><rgb name="radiance" value="8,7,6"/></emitter><ref name="exterior" id="fog"/></shape>
  <emitter type="constant"><rgb name="radiance" value="0.2,0.25,0.3"/></emitter>
</scene>)";

// A closed room lit only by a sky seen through a window pane, which next-event estimation
// cannot see through: every light path leaves through the pane by sampling (the case guiding is for).
inline const char* kWindowScene = R"(<scene version="3.0.0">
  <integrator type="path"><integer name="max_depth" value="8"/></integrator>
  <sensor type="perspective"><float name="fov" value="70"/>
    <transform name="to_world"><lookat origin="0,0,0.9" target="0,-0.2,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
      <rfilter type="box"/></film>
  </sensor>
  <bsdf type="diffuse" id="wall"><rgb name="reflectance" value="0.7,0.6,0.5"/></bsdf>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="-90"/><translate y="-1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate x="1" angle="90"/><translate y="1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><translate z="-1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="180"/><translate z="1"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><rotate y="1" angle="-90"/><translate x="1"/></transform>
    <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate y="1" angle="90"/><translate x="-1"/></transform>
    <bsdf type="thindielectric"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="0.25"/><rotate y="1" angle="90"/>
    <translate x="-1" y="0.75"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="1" y="0.25"/><rotate y="1" angle="90"/>
    <translate x="-1" y="-0.75"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.25" y="0.5"/><rotate y="1" angle="90"/>
    <translate x="-1" z="0.75"/></transform><ref id="wall"/></shape>
  <shape type="rectangle"><transform name="to_world"><scale x="0.25" y="0.5"/><rotate y="1" angle="90"/>
    <translate x="-1" z="-0.75"/></transform><ref id="wall"/></shape>
  <emitter type="constant"><rgb name="radiance" value="3,3,3.5"/></emitter>
</scene>)";

inline std::unique_ptr<Scene> window_scene() {
  LoadResult r = load_scene(parse_scene_string(kWindowScene, "window_scene.xml"), LoadOptions{});
  return std::move(r.scene);
}

inline std::unique_ptr<Scene> fog_scene() {
  LoadResult r = load_scene(parse_scene_string(kFogScene, "fog_scene.xml"), LoadOptions{});
  return std::move(r.scene);
}

/// The scene `xml` with each of `edits` (exact text, replacement) applied once, at its film size or
/// width x height when given.
inline std::unique_ptr<Scene> load_edited(std::string xml, const std::vector<std::pair<std::string, std::string>>& edits,
                                          int width = 0, int height = 0) {
  for (const auto& [from, to] : edits) {
    const size_t at = xml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) xml.replace(at, from.size(), to);
  }
  LoadOptions options;
  options.width = width;
  options.height = height;
  return load_scene(parse_scene_string(xml, "edited.xml"), options).scene;
}

}  // namespace tessera::test
