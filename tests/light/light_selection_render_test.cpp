// Light selection inside the integrators: the BVH and power strategies render the same image in
// expectation (channel means of the many-lights scene within a few standard errors), and the MIS
// weights are consistent: the direct integrator with light samples only, BSDF samples only, and
// both (MIS) agree on a scene of triangle and sphere lights, for both strategies.
#include "test_support.h"
#include "tessera/bsdf/diffuse.h"
#include "tessera/core/hash.h"
#include "tessera/light/area.h"
#include "tessera/sequence/renderer.h"
#include "tessera/render/scene.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

struct Means {
  double mean[3] = {0, 0, 0};
  double var_of_mean[3] = {0, 0, 0};  // of the image mean, from the pixels' sample variances
};

Means image_means(const Film& film) {
  Means m;
  const auto w = film.window();
  const double pixels = double(w.x1 - w.x0) * double(w.y1 - w.y0);
  for (int y = w.y0; y < w.y1; ++y)
    for (int x = w.x0; x < w.x1; ++x) {
      Rgb mean = film.mean({x, y}), var = film.sample_variance({x, y});
      double n = double(film.pixel({x, y}).count);
      for (int c = 0; c < 3; ++c) {
        m.mean[c] += mean[c] / pixels;
        m.var_of_mean[c] += double(var[c]) / n / (pixels * pixels);
      }
    }
  return m;
}

// Largest |difference| of channel means in standard errors.
double max_z(const Means& a, const Means& b) {
  double z = 0;
  for (int c = 0; c < 3; ++c)
    z = std::max(z, std::abs(a.mean[c] - b.mean[c]) / std::sqrt(a.var_of_mean[c] + b.var_of_mean[c]));
  return z;
}

std::string describe(const Means& a, const Means& b) {
  std::ostringstream s;
  for (int c = 0; c < 3; ++c)
    s << " [" << a.mean[c] << " +- " << std::sqrt(a.var_of_mean[c]) << " vs " << b.mean[c] << " +- "
      << std::sqrt(b.var_of_mean[c]) << "]";
  return s.str();
}

RenderSettings settings(int spp, uint32_t seed) {
  RenderSettings s;
  s.spp = spp;
  s.seed = seed;
  s.threads = 2;
  s.tile_size = 16;
  return s;
}

TEST(LightSelectionRender, ManyLightsBvhAndPowerAgree) {
  LoadOptions options;
  options.width = 64;
  options.height = 36;
  auto scene = load_scene(parse_scene_file(test::source_dir() + "/scenes/many-lights/scene.xml"), options).scene;
  scene->set_light_selection(LightSelection::Bvh);
  Means bvh = image_means(render(*scene, settings(64, 1)));
  scene->set_light_selection(LightSelection::Power);
  Means power = image_means(render(*scene, settings(64, 2)));
  EXPECT_LT(max_z(bvh, power), 4.0) << describe(bvh, power);
  // The hierarchy must also be the better estimator here (the point of having it).
  for (int c = 0; c < 3; ++c) EXPECT_LT(bvh.var_of_mean[c], power.var_of_mean[c]) << c;
}

// A diffuse wall at z = 4 facing the camera, lit by 60 small triangles and two spheres between it
// and the camera that emit towards it.
std::unique_ptr<Scene> lit_wall(int emitter_samples, int bsdf_samples) {
  auto scene = std::make_unique<Scene>();
  auto diffuse = make_diffuse_bsdf(std::make_shared<ConstantTexture>(Rgb(0.7f)));
  scene->bsdfs.push_back(diffuse);
  auto wall = std::make_shared<MeshData>();
  wall->positions = {{-4.f, -4.f, 4.f}, {4.f, -4.f, 4.f}, {4.f, 4.f, 4.f}, {-4.f, 4.f, 4.f}};
  wall->indices = {0, 2, 1, 0, 3, 2};  // normal -z
  scene->shapes.push_back(std::make_unique<TriangleMeshShape>(wall, false, true));
  scene->shapes.back()->bsdf = diffuse.get();

  Pcg32 rng(17);
  for (int group = 0; group < 2; ++group) {
    auto m = std::make_shared<MeshData>();
    for (int t = 0; t < 30; ++t) {
      Vec3 c(6.f * rng.next_float() - 3.f, 6.f * rng.next_float() - 3.f, 2.5f + rng.next_float());
      float e = 0.1f + 0.3f * rng.next_float();
      // Winding normal +z (towards the wall), tilted a little.
      Vec3 a = c + Vec3(-e, -e, 0.2f * e * (rng.next_float() - 0.5f)), b = c + Vec3(e, -e, 0.f), d = c + Vec3(0.f, e, 0.f);
      for (Vec3 v : {a, b, d}) m->positions.push_back(v);
      uint32_t i = uint32_t(m->positions.size());
      m->indices.insert(m->indices.end(), {i - 3, i - 2, i - 1});
    }
    scene->shapes.push_back(std::make_unique<TriangleMeshShape>(m, false, true));
    scene->lights.push_back(make_area_light(*scene->shapes.back(), group ? Rgb(3.f, 1.f, 0.5f) : Rgb(0.5f, 1.f, 2.f)));
    scene->shapes.back()->light = scene->lights.back().get();
  }
  for (int s = 0; s < 2; ++s) {
    scene->shapes.push_back(std::make_unique<SphereShape>(Vec3(s ? 1.5f : -2.f, 0.5f, 3.4f), 0.25f, false));
    scene->lights.push_back(make_area_light(*scene->shapes.back(), Rgb(2.f)));
    scene->shapes.back()->light = scene->lights.back().get();
  }
  scene->camera = make_perspective_camera(Transform(), 60.f, 24, 24, 1e-3f, 1e4f);
  scene->film.width = 24;
  scene->film.height = 24;
  scene->integrator.type = IntegratorType::Direct;
  scene->integrator.hide_emitters = true;  // compare the wall's lighting only
  scene->integrator.emitter_samples = emitter_samples;
  scene->integrator.bsdf_samples = bsdf_samples;
  scene->finalize();
  return scene;
}

TEST(LightSelectionRender, DirectLightOnlyBsdfOnlyAndMisAgree) {
  auto bsdf_only = lit_wall(0, 1);
  Means reference = image_means(render(*bsdf_only, settings(1024, 3)));
  for (LightSelection s : {LightSelection::Bvh, LightSelection::Power}) {
    auto light_only = lit_wall(1, 0);
    auto mis = lit_wall(1, 1);
    light_only->set_light_selection(s);
    mis->set_light_selection(s);
    Means l = image_means(render(*light_only, settings(256, 4)));
    Means m = image_means(render(*mis, settings(256, 5)));
    EXPECT_LT(max_z(reference, l), 4.0) << light_selection_name(s) << " light only:" << describe(reference, l);
    EXPECT_LT(max_z(reference, m), 4.0) << light_selection_name(s) << " MIS:" << describe(reference, m);
  }
}

}  // namespace
}  // namespace tessera
