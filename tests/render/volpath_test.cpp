// The volume path tracer against closed forms: Beer-Lambert through an absorbing slab (camera
// rays and shadow rays), and the furnace: an albedo-1 medium in a constant environment of radiance 1
// is invisible (every path escapes with weight 1), while an absorbing control is not.
#include "scene_builders.h"
#include "tessera/bsdf/null.h"
#include "tessera/light/constant.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using namespace tessera::test;

const Medium* add_medium(Scene& scene, Rgb sigma_t, Rgb albedo, float g = 0.f) {
  std::shared_ptr<const PhaseFunction> phase = g == 0.f ? make_isotropic_phase() : make_hg_phase(g);
  scene.media.push_back(make_homogeneous_medium(sigma_t, albedo, phase));
  return scene.media.back().get();
}

const Bsdf* add_null(Scene& scene) {
  scene.bsdfs.push_back(make_null_bsdf());
  return scene.bsdfs.back().get();
}

// A box [-h, h]^2 x [z0, z0 + depth] as a closed outward mesh, bounding `interior`.
Shape* add_box(Scene& scene, float h, float z0, float depth, const Bsdf* bsdf, const Medium* interior) {
  auto mesh = cube_mesh(1.f, /*inward=*/false);
  for (Vec3& p : mesh->positions) p = Vec3(p.x * h, p.y * h, z0 + (p.z + 1.f) * 0.5f * depth);
  scene.shapes.push_back(std::make_unique<TriangleMeshShape>(mesh, false, true));
  Shape* s = scene.shapes.back().get();
  s->bsdf = bsdf;
  s->interior = interior;
  s->medium_interface = true;
  return s;
}

void prepare(Scene& scene, int width, int height, float fov) {
  set_camera(scene, Vec3(0.f), fov, width, height);
  scene.film.filter = make_box_filter(0.5f);
  scene.sampler.type = SamplerType::Independent;
  scene.integrator.type = IntegratorType::VolPath;
  scene.finalize();
}

TEST(VolPath, CameraRaysThroughAnAbsorbingSlabFollowBeerLambert) {
  // Looking along +z through a slab 1.5 deep (null boundary) at a constant sky of radiance 1.
  Scene scene;
  const Rgb sigma(0.5f, 1.f, 2.f);
  add_box(scene, 50.f, 2.f, 1.5f, add_null(scene), add_medium(scene, sigma, Rgb(0.f)));
  scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
  prepare(scene, 8, 8, 1.f);  // near-parallel rays: path length 1.5 / cos(< 0.5 deg)
  ASSERT_TRUE(scene.has_media());
  Film film = render(scene, render_settings(4, 3));
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      Rgb m = film.mean({x, y});
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(m[c], std::exp(-sigma[c] * 1.5f), 1e-4f) << x << "," << y << " ch " << c;
    }

  // The path integrator ignores media: the slab is an invisible null surface.
  scene.integrator.type = IntegratorType::Path;
  Film plain = render(scene, render_settings(2, 3));
  EXPECT_NEAR(plain.mean({3, 3}).b, 1.f, 1e-6f);
}

TEST(VolPath, ShadowRaysThroughAnAbsorbingSlabFollowBeerLambert) {
  // A diffuse floor at z = 6 facing the camera, lit by a point light at the camera through a slab
  // between z = 2 and 3: the floor's radiance is rho/pi * I cos / d^2 * exp(-sigma * path in slab),
  // with the camera ray crossing the slab too.
  Scene scene;
  const Rgb sigma(0.2f, 0.6f, 1.2f);
  add_box(scene, 50.f, 2.f, 1.f, add_null(scene), add_medium(scene, sigma, Rgb(0.f)));
  auto floor = cube_mesh(1.f, false);
  floor->positions = {{-40.f, -40.f, 6.f}, {40.f, -40.f, 6.f}, {40.f, 40.f, 6.f}, {-40.f, 40.f, 6.f}};
  floor->indices = {0, 2, 1, 0, 3, 2};  // normal towards -z (the camera)
  scene.shapes.push_back(std::make_unique<TriangleMeshShape>(floor, false, true));
  scene.shapes.back()->bsdf = add_diffuse(scene, Rgb(0.5f));
  const float intensity = 36.f;
  scene.lights.push_back(make_point_light(Vec3(0.f, 0.f, 0.001f), Rgb(intensity)));
  prepare(scene, 5, 5, 2.f);
  Film film = render(scene, render_settings(16, 3));
  Rgb m = film.mean({2, 2});  // the central pixel: cos ~ 1, distance 6
  for (int c = 0; c < 3; ++c) {
    const float direct = 0.5f * kInvPi * intensity / (6.f * 6.f);
    EXPECT_NEAR(m[c], direct * std::exp(-2.f * sigma[c]), 2e-3f * direct) << "channel " << c;
  }
}

struct FurnaceCase {
  Rgb albedo;
  float g;
  bool lossless;
};

TEST(VolPath, AlbedoOneMediumInAFurnaceStaysOne) {
  for (const FurnaceCase& fc : {FurnaceCase{Rgb(1.f), 0.f, true}, FurnaceCase{Rgb(1.f), 0.7f, true},
                                FurnaceCase{Rgb(1.f), -0.4f, true}, FurnaceCase{Rgb(0.7f), 0.f, false}}) {
    Scene scene;
    // A dense sphere (optical radius 3) seen whole against the furnace.
    const Medium* m = add_medium(scene, Rgb(3.f, 2.f, 4.f), fc.albedo, fc.g);
    Shape* s = add_sphere(scene, Vec3(0.f, 0.f, 5.f), 1.f, false, add_null(scene));
    s->interior = m;
    s->medium_interface = true;
    scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(1.f)));
    prepare(scene, 16, 16, 20.f);
    Film film = render(scene, render_settings(64, 3));
    double sum[3] = {0, 0, 0}, var[3] = {0, 0, 0};
    int n = 0;
    for (int y = 5; y < 11; ++y)
      for (int x = 5; x < 11; ++x) {  // pixels well inside the sphere's silhouette
        Rgb mean = film.mean({x, y}), v = film.sample_variance({x, y});
        const double count = double(film.pixel({x, y}).count);
        for (int c = 0; c < 3; ++c) {
          sum[c] += mean[c];
          var[c] += v[c] / count;
        }
        ++n;
      }
    for (int c = 0; c < 3; ++c) {
      const double mean = sum[c] / n, se = std::sqrt(var[c]) / n;
      if (fc.lossless)
        EXPECT_NEAR(mean, 1.0, 4.0 * se + 1e-3) << "g " << fc.g << " channel " << c;
      else
        EXPECT_LT(mean, 0.9) << "the absorbing control must not pass for 1 (channel " << c << ")";
    }
  }
}

}  // namespace
}  // namespace tessera
