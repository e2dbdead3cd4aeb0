// orthographic sensor: the ray grid (origins on the image plane, one direction), the factory, and
// a render whose projected size and position are analytic.
#include "scene_builders.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using namespace tessera::test;

constexpr double kPiD = 3.14159265358979323846;

// Mitsuba's convention: camera-space x = 1 - 2 sx over the width (so +x on the LEFT), y = (1 - 2
// sy) / aspect over the height; to_world's scale sets the extent.
TEST(OrthographicCamera, RayGrid) {
  const int w = 200, h = 100;  // aspect 2
  const Transform xf = *Transform::look_at({1.f, 2.f, 3.f}, {1.f, 2.f, -7.f}, {0.f, 1.f, 0.f}) *
                       Transform::scale({2.5f, 2.5f, 1.f});
  auto cam = make_orthographic_camera(xf, w, h, 0.5f, 80.f);
  const Vec3 dir = normalize(xf.apply_vector({0.f, 0.f, 1.f}));
  EXPECT_NEAR(length(dir - Vec3(0.f, 0.f, -1.f)), 0.f, 1e-6f);
  for (int j = 0; j <= 10; ++j)
    for (int i = 0; i <= 10; ++i) {
      Vec2 raster(w * i / 10.f, h * j / 10.f);
      Ray r = cam->generate_ray(raster, {0.3f, 0.8f});
      float x = 1.f - 2.f * raster.x / w, y = (1.f - 2.f * raster.y / h) / 2.f;
      Vec3 expected = xf.apply_point({x, y, 0.f});
      EXPECT_NEAR(length(r.o - expected), 0.f, 1e-5f) << i << "," << j;
      EXPECT_EQ(r.d, dir);
      EXPECT_EQ(r.tmin, 0.5f);
      EXPECT_EQ(r.tmax, 80.f);
    }
  // Looking down -z with +y up: camera +x is world -x, on the left of the image; the extent is
  // 2 * 2.5 = 5 across and 2.5 high, centred on (1, 2).
  Ray left = cam->generate_ray({0.f, 50.f}, {}), right = cam->generate_ray({200.f, 50.f}, {});
  Ray top = cam->generate_ray({100.f, 0.f}, {});
  EXPECT_NEAR(left.o.x, 1.f - 2.5f, 1e-5f);
  EXPECT_NEAR(right.o.x, 1.f + 2.5f, 1e-5f);
  EXPECT_NEAR(top.o.y, 2.f + 1.25f, 1e-5f);
  EXPECT_NEAR(top.o.z, 3.f, 1e-6f);
}

TEST(OrthographicCamera, FactoryReadsMitsubaParameters) {
  LoadOptions o;
  const std::string xml = R"(<scene version="0.6.0"><sensor type="orthographic">
      <float name="nearClip" value="0.25"/><float name="farClip" value="40"/>
      <transform name="toWorld"><scale x="3" y="3"/><lookat origin="0,0,-5" target="0,0,0" up="0,1,0"/></transform>
      <film type="hdrfilm"><integer name="width" value="60"/><integer name="height" value="40"/></film>
      </sensor><shape type="sphere"/></scene>)";
  auto scene = load_scene(parse_scene_string(xml, "mem/ortho.xml"), o).scene;
  const Transform xf = *Transform::look_at({0.f, 0.f, -5.f}, {0.f, 0.f, 0.f}, {0.f, 1.f, 0.f}) *
                       Transform::scale({3.f, 3.f, 1.f});
  auto expected = make_orthographic_camera(xf, 60, 40, 0.25f, 40.f);
  for (Vec2 raster : {Vec2(0.f, 0.f), Vec2(13.5f, 27.25f), Vec2(60.f, 40.f)}) {
    Ray a = scene->camera->generate_ray(raster, {}), b = expected->generate_ray(raster, {});
    EXPECT_NEAR(length(a.o - b.o), 0.f, 1e-5f);
    EXPECT_NEAR(length(a.d - b.d), 0.f, 1e-6f);
    EXPECT_EQ(a.tmin, b.tmin);
    EXPECT_EQ(a.tmax, b.tmax);
  }
  // An orthographic sensor has no field of view: `fov` is not one of its parameters.
  const std::string with_fov = R"(<scene version="0.6.0"><sensor type="orthographic"><float name="fov" value="30"/>
      </sensor><shape type="sphere"/></scene>)";
  EXPECT_THROW(load_scene(parse_scene_string(with_fov, "mem/ortho_fov.xml"), o), UnsupportedError);
}

// An emitting sphere of radius r (radiance 1) on a black background covers pi r^2 k^2 pixels
// (k = pixels per world unit), wherever it is along the view direction and whatever its depth; its
// centroid lands where the camera convention puts it.
TEST(OrthographicCamera, RenderedSphereHasAnalyticSize) {
  const int w = 96, h = 64;  // aspect 1.5
  const float half_width = 2.f;  // to_world scale: x in [-2, 2], y in [-4/3, 4/3]
  const double k = w / (2.0 * half_width);
  struct Case {
    Vec3 center;
    float radius;
  };
  for (Case c : {Case{{0.f, 0.f, 5.f}, 0.5f}, Case{{0.7f, -0.4f, 9.f}, 0.3f}}) {
    Scene scene;
    Shape* s = add_sphere(scene, c.center, c.radius, false, add_diffuse(scene, Rgb(0.f)));
    add_area_light(scene, *s, Rgb(1.f));
    scene.camera = make_orthographic_camera(Transform::scale({half_width, half_width, 1.f}), w, h, 1e-2f, 1e4f);
    scene.film.width = w;
    scene.film.height = h;
    scene.film.filter = make_box_filter(0.5f);
    scene.sampler.type = SamplerType::Independent;
    scene.integrator.max_depth = 1;
    scene.finalize();
    RenderSettings rs;
    rs.spp = 64;
    rs.seed = 3;
    rs.threads = 2;
    Film film = render(scene, rs);
    double total = 0, cx = 0, cy = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        double v = film.mean({x, y}).g;
        total += v;
        cx += v * (x + 0.5);
        cy += v * (y + 0.5);
      }
    cx /= total;
    cy /= total;
    const double area = kPiD * c.radius * c.radius * k * k;
    // Only the ~2 pi r k edge pixels are noisy (binomial, 64 samples): ~0.1% of the area.
    EXPECT_NEAR(total, area, 0.005 * area) << "sphere at " << c.center.x << "," << c.center.y;
    // Camera-space x = 1 - 2 sx  ->  raster x = w (1 - x / half_width) / 2; y likewise with aspect.
    EXPECT_NEAR(cx, w * (1.0 - c.center.x / half_width) / 2.0, 0.05);
    EXPECT_NEAR(cy, h * (1.0 - c.center.y / half_width * (double(w) / h)) / 2.0, 0.05);
  }
}

}  // namespace
}  // namespace tessera
