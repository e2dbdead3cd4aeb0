// Integrators against closed-form answers.
#include "scene_builders.h"
#include "tessera/light/constant.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>

namespace tessera {
namespace {

using namespace tessera::test;

struct Check {
  double mean = 0;
  int pixels = 0, outliers = 0;
  std::string worst;
};

// Mean over the (selected) pixels, and how many pixels lie further than `sigmas` standard errors
// (from the film's own sums of squares) from `expected`. Averages the three channels.
Check check_film(const Film& film, double expected, double sigmas,
                 const std::function<bool(Vec2i)>& select = {}) {
  Check c;
  double worst_z = -1;
  for (int y = film.window().y0; y < film.window().y1; ++y)
    for (int x = film.window().x0; x < film.window().x1; ++x) {
      if (select && !select({x, y})) continue;
      Rgb m = film.mean({x, y});
      Rgb v = film.sample_variance({x, y});
      double n = double(film.pixel({x, y}).count);
      for (int ch = 0; ch < 3; ++ch) {
        c.mean += m[ch] / 3.0;
        double se = std::sqrt(double(v[ch]) / n);
        // Some estimators here have (almost) zero variance; float rounding then dominates.
        double z = std::abs(m[ch] - expected) / std::max(se, 1e-5 * std::max(expected, 1e-3));
        if (z > sigmas) ++c.outliers;
        if (z > worst_z) {
          worst_z = z;
          std::ostringstream s;
          s << "pixel (" << x << "," << y << ") channel " << ch << ": " << m[ch] << " +- " << se << " (" << z
            << " sigma)";
          c.worst = s.str();
        }
      }
      ++c.pixels;
    }
  c.mean /= std::max(c.pixels, 1);
  return c;
}

RenderSettings settings(int spp) { return test::render_settings(spp); }

// Inside a closed diffuse sphere of radius 1 and albedo rho with a point light of intensity pi at
// its centre, irradiance from the light is pi everywhere, so L = rho (1 + L): L = rho / (1 - rho),
// 1 for rho = 0.5. Bounded depths give partial sums: depth 2 -> rho, 3 -> rho + rho^2, ...
std::unique_ptr<Scene> point_in_sphere(int max_depth, IntegratorType type = IntegratorType::Path) {
  auto scene = std::make_unique<Scene>();
  add_sphere(*scene, Vec3(0.f), 1.f, /*flip=*/true, add_diffuse(*scene, Rgb(0.5f)));
  scene->lights.push_back(make_point_light(Vec3(0.f), Rgb(kPi)));
  set_camera(*scene, Vec3(0.f, 0.f, 0.f), 70.f, 24, 20);
  scene->integrator.type = type;
  scene->integrator.max_depth = max_depth;
  scene->finalize();
  return scene;
}

TEST(PathIntegrator, PointLightInsideSphereConvergesToOne) {
  auto scene = point_in_sphere(-1);
  RenderStats stats;
  Film film = render(*scene, settings(256), {}, &stats);
  Check c = check_film(film, 1.0, 4.0);
  EXPECT_NEAR(c.mean, 1.0, 0.01);
  EXPECT_EQ(c.outliers, 0) << "worst " << c.worst;
  EXPECT_EQ(stats.counters.nonfinite, 0u);
  EXPECT_EQ(stats.counters.samples, uint64_t(24 * 20 * 256));
  EXPECT_EQ(stats.counters.camera_rays, uint64_t(24 * 20 * 256));
  EXPECT_GT(stats.counters.shadow_rays, stats.counters.camera_rays);
  EXPECT_GT(stats.counters.bounce_rays, stats.counters.camera_rays);
}

TEST(PathIntegrator, MaxDepthCountsLikeMitsuba) {
  // max_depth 1: only directly visible emitters (a point light is never visible): black.
  Film f1 = render(*point_in_sphere(1), settings(4));
  EXPECT_EQ(check_film(f1, 0.0, 1.0).mean, 0.0);
  // 2: direct illumination only, exactly rho with a point light (no variance at all).
  Film f2 = render(*point_in_sphere(2), settings(4));
  Check c2 = check_film(f2, 0.5, 1.0);
  EXPECT_NEAR(c2.mean, 0.5, 1e-5);
  // 3 and 4: one and two indirect bounces.
  Film f3 = render(*point_in_sphere(3), settings(64));
  EXPECT_NEAR(check_film(f3, 0.75, 4.0).mean, 0.75, 0.0075);
  Film f4 = render(*point_in_sphere(4), settings(64));
  EXPECT_NEAR(check_film(f4, 0.875, 4.0).mean, 0.875, 0.00875);
  // 0: nothing.
  Film f0 = render(*point_in_sphere(0), settings(1));
  EXPECT_EQ(check_film(f0, 0.0, 1.0).mean, 0.0);
}

TEST(DirectIntegrator, PointLightInsideSphereIsDirectOnly) {
  Film film = render(*point_in_sphere(-1, IntegratorType::Direct), settings(4));
  EXPECT_NEAR(check_film(film, 0.5, 1.0).mean, 0.5, 1e-5);
}

// A closed sphere whose inside both reflects (rho) and emits (Le): L = Le / (1 - rho). Exercises
// area-light sampling, emitter hits and their MIS combination.
std::unique_ptr<Scene> glowing_sphere(int max_depth, bool hide_emitters, IntegratorType type,
                                      bool cube = false) {
  auto scene = std::make_unique<Scene>();
  const Bsdf* bsdf = add_diffuse(*scene, Rgb(0.5f));
  Shape* shape;
  if (cube) {
    scene->shapes.push_back(std::make_unique<TriangleMeshShape>(cube_mesh(1.f, true), false, true));
    shape = scene->shapes.back().get();
    shape->bsdf = bsdf;
  } else {
    shape = add_sphere(*scene, Vec3(0.f), 1.f, true, bsdf);
  }
  add_area_light(*scene, *shape, Rgb(0.5f));
  set_camera(*scene, Vec3(0.1f, -0.2f, 0.05f), 80.f, 20, 16);
  scene->integrator.type = type;
  scene->integrator.max_depth = max_depth;
  scene->integrator.hide_emitters = hide_emitters;
  scene->finalize();
  return scene;
}

TEST(PathIntegrator, EmittingSphereConvergesAnalytically) {
  Film film = render(*glowing_sphere(-1, false, IntegratorType::Path), settings(256));
  Check c = check_film(film, 1.0, 4.0);
  EXPECT_NEAR(c.mean, 1.0, 0.01);
  EXPECT_EQ(c.outliers, 0) << "worst " << c.worst;
}

TEST(PathIntegrator, EmittingCubeMeshConvergesAnalytically) {
  Film film = render(*glowing_sphere(-1, false, IntegratorType::Path, /*cube=*/true), settings(256));
  Check c = check_film(film, 1.0, 4.0);
  EXPECT_NEAR(c.mean, 1.0, 0.01);
  EXPECT_EQ(c.outliers, 0) << "worst " << c.worst;
}

TEST(PathIntegrator, HideEmittersAndDepthTwo) {
  // Hidden: only the reflected part, rho Le / (1 - rho) = 0.5.
  Film hidden = render(*glowing_sphere(-1, true, IntegratorType::Path), settings(128));
  EXPECT_NEAR(check_film(hidden, 0.5, 4.0).mean, 0.5, 0.005);
  // Depth 2: Le + rho Le = 0.75, with NEE and BSDF sampling combined by MIS.
  Film direct = render(*glowing_sphere(2, false, IntegratorType::Path), settings(128));
  Check c = check_film(direct, 0.75, 4.0);
  EXPECT_NEAR(c.mean, 0.75, 0.0075);
  EXPECT_EQ(c.outliers, 0) << "worst " << c.worst;
}

TEST(DirectIntegrator, EmittingSphereWithSeveralSampleCounts) {
  for (auto [nl, nb] : {std::pair{1, 1}, std::pair{3, 1}, std::pair{1, 4}, std::pair{2, 0}, std::pair{0, 2}}) {
    auto scene = glowing_sphere(-1, false, IntegratorType::Direct);
    scene->integrator.emitter_samples = nl;
    scene->integrator.bsdf_samples = nb;
    Film film = render(*scene, settings(64));
    Check c = check_film(film, 0.75, 4.0);
    EXPECT_NEAR(c.mean, 0.75, 0.0075) << nl << " emitter / " << nb << " bsdf samples";
    EXPECT_EQ(c.outliers, 0) << nl << "/" << nb << " worst " << c.worst;
  }
}

// White furnace: a diffuse sphere of albedo 1 under a constant environment of radiance 1 is
// exactly 1 everywhere; a sphere of albedo 0.5 is 0.5 (a missing object would show 1).
std::unique_ptr<Scene> furnace(float albedo, IntegratorType type) {
  auto scene = std::make_unique<Scene>();
  add_sphere(*scene, Vec3(0.f, 0.f, 3.f), 1.f, false, add_diffuse(*scene, Rgb(albedo)));
  scene->lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
  set_camera(*scene, Vec3(0.f), 45.f, 24, 24);
  scene->integrator.type = type;
  scene->finalize();
  return scene;
}

// Pixels whose whole footprint (box filter: the pixel square) sees the object.
std::function<bool(Vec2i)> object_pixels(const Scene& scene) {
  return [&scene](Vec2i p) {
    for (float dx : {0.f, 1.f})
      for (float dy : {0.f, 1.f}) {
        SurfaceInteraction si;
        if (!scene.intersect(scene.camera->generate_ray({p.x + dx, p.y + dy}, {}), si)) return false;
      }
    return true;
  };
}

TEST(PathIntegrator, WhiteFurnace) {
  for (float albedo : {1.f, 0.5f}) {
    auto scene = furnace(albedo, IntegratorType::Path);
    Film film = render(*scene, settings(64));
    Check c = check_film(film, albedo, 4.0, object_pixels(*scene));
    EXPECT_GT(c.pixels, 200);
    EXPECT_NEAR(c.mean, albedo, 0.01 * albedo);
    EXPECT_EQ(c.outliers, 0) << "albedo " << albedo << " worst " << c.worst;
    // The background is the environment itself.
    EXPECT_NEAR(film.mean({0, 0}).g, 1.f, 1e-6f);
  }
}

TEST(DirectIntegrator, WhiteFurnace) {
  // One bounce off a convex object: the direct integrator is exact here too.
  for (float albedo : {1.f, 0.5f}) {
    auto scene = furnace(albedo, IntegratorType::Direct);
    Film film = render(*scene, settings(64));
    Check c = check_film(film, albedo, 4.0, object_pixels(*scene));
    EXPECT_NEAR(c.mean, albedo, 0.01 * albedo);
    EXPECT_EQ(c.outliers, 0) << "albedo " << albedo << " worst " << c.worst;
  }
}

TEST(PathIntegrator, HiddenEmittersLeaveBackgroundBlack) {
  auto scene = furnace(0.5f, IntegratorType::Path);
  scene->integrator.hide_emitters = true;
  Film film = render(*scene, settings(4));
  EXPECT_EQ(film.mean({0, 0}), Rgb());
  Check c = check_film(film, 0.5, 4.0, object_pixels(*scene));
  EXPECT_NEAR(c.mean, 0.5, 0.02);
}

// A spherical lamp above a diffuse floor: the irradiance at a floor point that sees the whole
// sphere is pi Le sin^2(theta_max) cos(theta), so with depth 2 the floor shows
// rho Le (r/d)^2 cos(theta). Exercises cone sampling of sphere lights and its pdf in MIS.
std::unique_ptr<Scene> sphere_lamp_over_floor(IntegratorType type) {
  auto scene = std::make_unique<Scene>();
  auto floor = std::make_shared<MeshData>();
  floor->positions = {{-50.f, -50.f, 0.f}, {50.f, -50.f, 0.f}, {50.f, 50.f, 0.f}, {-50.f, 50.f, 0.f}};
  floor->indices = {0, 1, 2, 0, 2, 3};  // normal +z
  scene->shapes.push_back(std::make_unique<TriangleMeshShape>(floor, false, true));
  scene->shapes.back()->bsdf = add_diffuse(*scene, Rgb(0.8f));
  // A big, close lamp so that BSDF sampling carries real weight in the MIS combination.
  Shape* lamp = add_sphere(*scene, Vec3(0.f, 0.f, 3.f), 1.5f, false, add_diffuse(*scene, Rgb(0.f)));
  add_area_light(*scene, *lamp, Rgb(4.f));
  auto xf = Transform::look_at({0.f, -4.f, 1.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 1.f});  // lamp out of view
  scene->camera = make_perspective_camera(*xf, 30.f, 20, 16, 1e-3f, 1e4f);
  scene->film.width = 20;
  scene->film.height = 16;
  scene->integrator.type = type;
  scene->integrator.max_depth = 2;
  scene->finalize();
  return scene;
}

TEST(Integrators, SphereLampOverFloorMatchesClosedForm) {
  for (IntegratorType type : {IntegratorType::Path, IntegratorType::Direct}) {
    auto scene = sphere_lamp_over_floor(type);
    Film film = render(*scene, settings(64));
    int outliers = 0;
    double sum = 0, sum_expected = 0;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 20; ++x) {
        // Expected value: the closed form averaged over the pixel's footprint (box filter).
        double expected = 0;
        for (int j = 0; j < 4; ++j)
          for (int i = 0; i < 4; ++i) {
            Ray r = scene->camera->generate_ray({x + (i + 0.5f) / 4.f, y + (j + 0.5f) / 4.f}, {});
            Vec3 p = r.at(-r.o.z / r.d.z);
            Vec3 to_c = Vec3(0.f, 0.f, 3.f) - p;
            double d2 = length_squared(to_c);
            expected += 0.8 * 4.0 * 2.25 / d2 * (to_c.z / std::sqrt(d2)) / 16.0;
          }
        Rgb m = film.mean({x, y});
        double se = std::sqrt(film.sample_variance({x, y}).g / double(film.pixel({x, y}).count));
        // The footprint average of the closed form is itself approximate (4x4 points): allow 0.5%.
        if (std::abs(m.g - expected) > 4 * se + 0.005 * expected) {
          ++outliers;
          if (outliers < 6) ADD_FAILURE() << x << "," << y << ": " << m.g << " +- " << se << " expected " << expected;
        }
        sum += m.g;
        sum_expected += expected;
      }
    EXPECT_EQ(outliers, 0) << (type == IntegratorType::Path ? "path" : "direct");
    EXPECT_NEAR(sum / sum_expected, 1.0, 0.01);
  }
}

}  // namespace
}  // namespace tessera
