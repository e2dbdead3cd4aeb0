// Interpolated shading normals against the geometry: a plane whose vertex normals lean 40 degrees
// towards +x. Light from below the geometric surface must never leak through it (whatever
// strictNormals says), and a viewer above the geometry but below the shading hemisphere sees the
// plane shaded with its geometric normal (no black seam), unless strictNormals drops the hit as
// Mitsuba 0.6 does.
#include "scene_builders.h"
#include "tessera/light/constant.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using namespace tessera::test;

std::unique_ptr<Scene> leaning_plane(Vec3 eye, Vec3 target, float fov, bool strict) {
  auto scene = std::make_unique<Scene>();
  auto m = std::make_shared<MeshData>();
  const float h = 10.f;
  m->positions = {{-h, -h, 0.f}, {h, -h, 0.f}, {h, h, 0.f}, {-h, h, 0.f}};
  m->indices = {0, 1, 2, 0, 2, 3};
  const float a = 40.f * kPi / 180.f;
  m->normals.assign(4, Vec3(std::sin(a), 0.f, std::cos(a)));
  scene->shapes.push_back(std::make_unique<TriangleMeshShape>(m, false, false));
  scene->shapes.back()->bsdf = add_diffuse(*scene, Rgb(0.5f));
  scene->camera = make_perspective_camera(*Transform::look_at(eye, target, Vec3(0.f, 1.f, 0.f)), fov, 8, 8,
                                          1e-3f, 1e4f);
  scene->film.width = scene->film.height = 8;
  scene->integrator.strict_normals = strict;
  return scene;
}

RenderSettings settings(int spp) {
  RenderSettings s;
  s.spp = spp;
  s.seed = 5;
  return s;
}

TEST(ShadingNormals, LightBelowTheGeometryNeverLeaksThrough) {
  for (bool strict : {false, true}) {
    // The light is under the plane, yet above the leaning shading hemisphere of the points seen.
    auto scene = leaning_plane(Vec3(0.f, 0.f, 2.f), Vec3(0.f), 30.f, strict);
    scene->lights.push_back(make_point_light(Vec3(5.f, 0.f, -1.f), Rgb(100.f)));
    scene->finalize();
    RenderStats stats;
    Film film = render(*scene, settings(4), {}, &stats);
    EXPECT_GT(stats.counters.shadow_rays + stats.counters.bounce_rays, 0u);
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) EXPECT_EQ(film.mean({x, y}).g, 0.f) << x << "," << y << " strict " << strict;
  }
}

TEST(ShadingNormals, ViewerBelowTheShadingHemisphereSeesGeometricShading) {
  // Seen at about 11 degrees above the plane from -x: above the geometry, below the shading
  // hemisphere (which leans towards +x). Under a constant sky of 1, direct light only, a diffuse
  // plane of albedo 0.5 shaded with its geometric normal reflects exactly 0.5.
  for (bool strict : {false, true}) {
    auto scene = leaning_plane(Vec3(-5.f, 0.f, 1.f), Vec3(0.f), 5.f, strict);
    scene->lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
    scene->integrator.max_depth = 2;
    scene->integrator.hide_emitters = true;
    scene->finalize();
    RenderStats stats;
    Film film = render(*scene, settings(64), {}, &stats);
    double sum = 0;
    int black = 0;
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        float v = film.mean({x, y}).g;
        sum += v;
        black += v == 0.f;
      }
    if (strict) {
      EXPECT_EQ(sum, 0.0) << "strictNormals drops the hit, as Mitsuba 0.6";
    } else {
      EXPECT_EQ(black, 0);
      EXPECT_NEAR(sum / 64, 0.5, 0.02);
    }
    EXPECT_EQ(stats.counters.nonfinite, 0u);
  }
}

}  // namespace
}  // namespace tessera
