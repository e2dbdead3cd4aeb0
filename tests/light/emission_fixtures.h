// One emitter of every kind, set up for the emission-sampling tests (Light::sample_le/pdf_le), with
// the power each one emits computed independently of its sampler.
#pragma once

#include "tessera/core/hash.h"
#include "tessera/core/transform.h"
#include "tessera/image/image.h"
#include "tessera/light/area.h"
#include "tessera/light/constant.h"
#include "tessera/light/directional.h"
#include "tessera/light/envmap.h"
#include "tessera/light/point.h"
#include "tessera/light/spot.h"
#include "tessera/light/sunsky.h"
#include "tessera/light/triangle_light.h"
#include "tessera/render/shape.h"

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace tessera::test {

inline constexpr double kEmPi = 3.14159265358979323846;

/// The scene the distant lights are preprocessed with: bounding sphere centre (1, -0.5, 1.5).
inline Bounds3 emission_scene_bounds() {
  Bounds3 b;
  b.extend(Vec3(-1.f, -2.f, 0.5f));
  b.extend(Vec3(3.f, 1.f, 2.5f));
  return b;
}
inline double emission_scene_radius() { return 0.5 * double(length(emission_scene_bounds().diagonal())); }

enum class EmitterKind { Area, Point, Spot, Directional, Distant };

struct EmitterCase {
  std::string name;
  EmitterKind kind;
  std::unique_ptr<Light> light;
  Rgb power;                      // emitted power, per channel
  Vec3 axis = Vec3(0.f, 0.f, 1.f);  // spot: its world axis (the chi-square bins are set around it)
  double cos_cutoff = -1.0;         // spot: cosine of its cutoff angle
};

/// A bent quad (two triangles that are not coplanar), so that its two normals differ.
inline std::shared_ptr<MeshData> bent_quad() {
  auto m = std::make_shared<MeshData>();
  m->positions = {{0.f, 0.f, 0.f}, {2.f, 0.f, 0.f}, {2.f, 1.f, 0.5f}, {0.f, 1.5f, -0.3f}};
  m->indices = {0, 1, 2, 0, 2, 3};
  return m;
}

/// An 8x5 map, smooth gradient plus one bright texel, so that its sampling is far from uniform.
inline Image emission_test_map() {
  Image img(8, 5, 3);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 8; ++x) img.set_rgb(x, y, Rgb(0.1f + 0.05f * x, 0.2f + 0.1f * y, 0.3f));
  img.set_rgb(5, 1, Rgb(40.f, 20.f, 10.f));
  return img;
}

/// Radiance integrated over the sphere of directions, by the midpoint rule in (u, v) of the
/// lat-long parametrisation (d omega = 2 pi^2 sin(pi v) du dv): independent of the sampler.
inline Rgb radiance_over_sphere(const Light& light, int nu = 1200, int nv = 600) {
  double sum[3] = {0, 0, 0};
  for (int j = 0; j < nv; ++j) {
    const double v = (j + 0.5) / nv, w = 2.0 * kEmPi * kEmPi * std::sin(kEmPi * v) / (double(nu) * nv);
    for (int i = 0; i < nu; ++i) {
      const double u = (i + 0.5) / nu;
      const Vec3 d(float(std::sin(2 * kEmPi * u) * std::sin(kEmPi * v)), float(std::cos(kEmPi * v)),
                   float(-std::cos(2 * kEmPi * u) * std::sin(kEmPi * v)));
      const Rgb l = light.le_env(d);
      for (int c = 0; c < 3; ++c) sum[c] += w * double(l[c]);
    }
  }
  return Rgb(float(sum[0]), float(sum[1]), float(sum[2]));
}

/// Shapes the area lights need; they must outlive the lights.
struct EmitterShapes {
  SphereShape sphere{Vec3(0.5f, 1.f, -0.3f), 0.7f, false};
  SphereShape inward{Vec3(-2.f, 0.f, 1.f), 1.3f, true};
  TriangleMeshShape quad{bent_quad(), false, true};
  TriangleMeshShape quad_flipped{bent_quad(), true, true};
};

/// Every emitter kind, distant ones preprocessed with emission_scene_bounds().
inline std::vector<EmitterCase> make_emitter_cases(const EmitterShapes& s) {
  std::vector<EmitterCase> out;
  const Rgb l(1.f, 2.f, 3.f);
  auto area = [&](const char* name, std::unique_ptr<Light> light, double area) {
    out.push_back({name, EmitterKind::Area, std::move(light), l * float(kEmPi * area)});
  };
  area("area sphere", make_area_light(s.sphere, l), s.sphere.area());
  area("area sphere, inward", make_area_light(s.inward, l), s.inward.area());
  area("area mesh", make_area_light(s.quad, l), s.quad.area());
  auto tri = make_triangle_light(s.quad_flipped, 1, l);
  const float tri_area = length(cross(Vec3(2.f, 1.f, 0.5f), Vec3(0.f, 1.5f, -0.3f))) * 0.5f;
  area("triangle, flipped", std::move(tri), tri_area);

  const Rgb i(4.f, 2.f, 1.f);
  out.push_back({"point", EmitterKind::Point, make_point_light(Vec3(0.3f, -0.2f, 1.f), i), i * float(4.0 * kEmPi)});
  const Transform aim = *Transform::look_at({1.f, 2.f, 3.f}, {-1.f, 0.5f, 0.f}, {0.f, 0.f, 1.f});
  const Vec3 axis = normalize(aim.apply_vector(Vec3(0.f, 0.f, 1.f)));
  const double deg = kEmPi / 180.0;
  auto spot = [&](const char* name, float cutoff, float beam) {
    out.push_back({name, EmitterKind::Spot, make_spot_light(aim, i, cutoff, beam),
                   i * float(spot_profile_solid_angle(cutoff * deg, beam * deg)), axis, std::cos(cutoff * deg)});
  };
  spot("spot 50/30", 50.f, 30.f);
  spot("spot 25/25", 25.f, 25.f);
  spot("spot 150/10", 150.f, 10.f);

  const double disk = kEmPi * emission_scene_radius() * emission_scene_radius();
  const Rgb e(0.5f, 1.f, 2.f);
  out.push_back({"directional", EmitterKind::Directional, make_directional_light(Vec3(1.f, -2.f, 0.5f), e),
                 e * float(disk)});
  out.push_back({"constant", EmitterKind::Distant, std::make_unique<ConstantLight>(l), l * float(4.0 * kEmPi * disk)});
  auto env = std::make_unique<EnvmapLight>(emission_test_map(), 1.5f,
                                           Transform::rotate(normalize(Vec3(1.f, 2.f, -0.5f)), 70.f));
  out.push_back({"envmap", EmitterKind::Distant, std::move(env), Rgb()});

  SunskySettings sky;
  sky.sun = {55.0 * deg, 120.0 * deg};
  sky.resolution = 128;
  sky.sun_radius_scale = 30.0;  // a disk the chi-square bins can resolve
  sky.to_world = Transform::rotate(normalize(Vec3(1.f, 0.5f, 0.f)), 30.f);
  out.push_back({"sunsky map", EmitterKind::Distant, make_sunsky_lights(sky).map, Rgb()});
  sky.sun_radius_scale = 0.0;  // the sun as a directional light beside the sky map
  SunskyLights split = make_sunsky_lights(sky);
  out.push_back({"sunsky sky", EmitterKind::Distant, std::move(split.map), Rgb()});
  const Rgb sun = sunsky_sun_irradiance(sky);
  out.push_back({"sunsky sun", EmitterKind::Directional, std::move(split.directional), sun * float(disk)});

  for (EmitterCase& c : out) {
    c.light->preprocess(emission_scene_bounds());
    if (c.kind == EmitterKind::Distant && c.power.is_black()) c.power = radiance_over_sphere(*c.light) * float(disk);
  }
  return out;
}

}  // namespace tessera::test
