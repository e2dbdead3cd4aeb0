// Emission sampling (Light::sample_le / pdf_le) of every emitter: the directions follow pdf_dir
// (chi-square), sample_le and pdf_le report the same densities, and the rays start where the
// contract says (on the shape's emitting side; on the disk behind the scene for distant lights).
#include "light/emission_fixtures.h"
#include "support/chi2.h"

#include "tessera/core/frame.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

using test::EmitterCase;
using test::EmitterKind;

bool finite(const LightEmission& e) {
  return is_finite(e.p) && is_finite(e.n) && is_finite(e.dir) && e.le.is_finite() && std::isfinite(e.pdf_pos) &&
         std::isfinite(e.pdf_dir);
}

/// How directions are shown to the chi-square harness, which bins the sphere in (cos theta, phi)
/// about +z: rotated into a frame around the normal at the fixed point of an area light or around a
/// spot's axis (rotations keep solid angle), and for spots stretched from the cone to the sphere,
/// cos theta -> 1 - 2 (1 - cos theta) / (1 - cos cutoff). The stretch maps the uniform cone onto
/// the uniform sphere and scales densities by (1 - cos cutoff) / 2; without it the cone's edge
/// would be a step inside a row of bins, which the harness's Simpson integration cannot resolve.
struct View {
  Frame frame;
  double cos_cutoff = -1.0;  // -1: no stretch

  double scale() const { return 0.5 * (1.0 - cos_cutoff); }
  Vec3 to_view(Vec3 dir) const { return restretch(frame.to_local(dir), 1.0 / scale()); }
  Vec3 from_view(Vec3 w) const { return frame.to_world(restretch(w, scale())); }

 private:
  /// Scales 1 - cos theta by `k`, keeping phi.
  static Vec3 restretch(Vec3 w, double k) {
    if (k == 1.0) return w;
    const double c = 1.0 - (1.0 - double(w.z)) * k, s = std::sqrt(std::max(0.0, 1.0 - c * c));
    const double r = std::sqrt(double(w.x) * w.x + double(w.y) * w.y);
    if (!(r > 0.0)) return Vec3(0.f, 0.f, float(c));
    return Vec3(float(w.x * s / r), float(w.y * s / r), float(c));
  }
};

View view_of(const EmitterCase& c, const LightEmission& first) {
  if (c.kind == EmitterKind::Area) return {Frame(first.n)};
  if (c.kind == EmitterKind::Spot) return {Frame(c.axis), c.cos_cutoff};
  return {};
}

test::Chi2Options options(const EmitterCase& c, int test_count, uint64_t seed) {
  test::Chi2Options o;
  o.name = c.name;
  o.test_count = test_count;
  o.seed = seed;  // a sequence of its own per case: the tests are independent
  // Tabulated maps have steps inside bins: integrate them finely (the others are smooth).
  o.integration_resolution = c.kind == EmitterKind::Distant ? 32 : 8;
  return o;
}

TEST(EmissionSampling, DirectionsFollowPdfDir) {
  test::EmitterShapes shapes;
  std::vector<EmitterCase> cases = test::make_emitter_cases(shapes);
  int count = 0;
  for (const EmitterCase& c : cases) count += c.kind != EmitterKind::Directional;
  uint64_t seed = 0;
  for (const EmitterCase& c : cases) {
    if (c.kind == EmitterKind::Directional) continue;  // a delta direction: see DirectionalIsADelta
    const Light& light = *c.light;
    // Area lights: the point stays fixed (u_pos), only the direction is drawn.
    const Vec2 u_pos(0.37f, 0.81f);
    LightEmission first;
    ASSERT_TRUE(light.sample_le(u_pos, Vec2(0.5f, 0.5f), first)) << c.name;
    const View view = view_of(c, first);
    auto r = test::chi2_test(
        [&](Vec2 u) {
          LightEmission e;
          if (!light.sample_le(u_pos, u, e)) return test::Chi2Sample{Vec3(), 0.f, false};
          return test::Chi2Sample{view.to_view(e.dir), float(e.pdf_dir * view.scale())};
        },
        [&](Vec3 w) {
          float pdf_pos = 0.f, pdf_dir = 0.f;
          light.pdf_le(first.p, first.n, view.from_view(w), pdf_pos, pdf_dir);
          return double(pdf_dir) * view.scale();
        },
        options(c, count, ++seed));
    EXPECT_TRUE(r.passed) << r.message;
    // Every sampler here draws from a normalised density over its directions.
    EXPECT_NEAR(r.pdf_integral, 1.0, 2e-3) << c.name;
    std::printf("[ chi2 ] %s: statistic %.1f, dof %d, p %.3f\n", c.name.c_str(), r.statistic, r.dof, r.p_value);
  }
}

TEST(EmissionSampling, SampleAndPdfAgree) {
  test::EmitterShapes shapes;
  for (const EmitterCase& c : test::make_emitter_cases(shapes)) {
    Pcg32 rng(11);
    int valid = 0;
    for (int n = 0; n < 20000; ++n) {
      const Vec2 u_pos(rng.next_float(), rng.next_float()), u_dir(rng.next_float(), rng.next_float());
      LightEmission e;
      if (!c.light->sample_le(u_pos, u_dir, e)) continue;
      ++valid;
      ASSERT_TRUE(finite(e)) << c.name;
      ASSERT_NEAR(length(e.dir), 1.f, 1e-5f) << c.name;
      ASSERT_GT(e.pdf_pos, 0.f) << c.name;
      ASSERT_GT(e.pdf_dir, 0.f) << c.name;
      float pdf_pos = -1.f, pdf_dir = -1.f;
      c.light->pdf_le(e.p, e.n, e.dir, pdf_pos, pdf_dir);
      ASSERT_NEAR(pdf_pos, e.pdf_pos, 1e-4f * e.pdf_pos) << c.name << " sample " << n;
      ASSERT_NEAR(pdf_dir, e.pdf_dir, 1e-4f * e.pdf_dir) << c.name << " sample " << n;
      EXPECT_EQ(e.infinite, c.kind == EmitterKind::Distant || c.kind == EmitterKind::Directional) << c.name;
      EXPECT_EQ(e.delta_pos, c.kind == EmitterKind::Point || c.kind == EmitterKind::Spot) << c.name;
      EXPECT_EQ(e.delta_dir, c.kind == EmitterKind::Directional) << c.name;
    }
    // Only a ray that grazes a surface or a float cone edge may fail.
    EXPECT_GT(valid, 19990) << c.name;
  }
}

TEST(EmissionSampling, AreaRaysLeaveTheEmittingSideOfTheShape) {
  test::EmitterShapes shapes;
  const std::vector<EmitterCase> cases = test::make_emitter_cases(shapes);
  const SphereShape* spheres[2] = {&shapes.sphere, &shapes.inward};
  Pcg32 rng(3);
  for (int k = 0; k < 2; ++k) {
    const SphereShape& s = *spheres[k];
    for (int n = 0; n < 2000; ++n) {
      LightEmission e;
      ASSERT_TRUE(cases[size_t(k)].light->sample_le({rng.next_float(), rng.next_float()},
                                                    {rng.next_float(), rng.next_float()}, e));
      EXPECT_NEAR(length(e.p - s.center()), s.radius(), 1e-5f);
      const Vec3 outward = normalize(e.p - s.center());
      EXPECT_GT(dot(e.n, outward) * (k == 1 ? -1.f : 1.f), 0.999f);  // the inward sphere emits inwards
      EXPECT_GT(dot(e.n, e.dir), 0.f);
      EXPECT_NEAR(e.pdf_pos, 1.f / s.area(), 1e-6f);  // uniform by area, not the cone of sample_li
      EXPECT_GT(e.p_error.x, 0.f);                    // reprojected onto the sphere, with its bound
    }
  }
  // The flipped triangle emits to the side opposite the normal its winding gives.
  const Vec3 wound = normalize(cross(Vec3(2.f, 1.f, 0.5f), Vec3(0.f, 1.5f, -0.3f)));
  for (int n = 0; n < 200; ++n) {
    LightEmission e;
    ASSERT_TRUE(cases[3].light->sample_le({rng.next_float(), rng.next_float()}, {rng.next_float(), rng.next_float()}, e));
    EXPECT_NEAR(dot(e.n, wound), -1.f, 1e-5f);
    EXPECT_LT(dot(e.dir, wound), 0.f);
  }
}

TEST(EmissionSampling, DistantRaysStartOnTheDiskBehindTheScene) {
  test::EmitterShapes shapes;
  const Vec3 center = test::emission_scene_bounds().center();
  const float radius = float(test::emission_scene_radius());
  for (const EmitterCase& c : test::make_emitter_cases(shapes)) {
    if (c.kind != EmitterKind::Distant && c.kind != EmitterKind::Directional) continue;
    Pcg32 rng(5);
    for (int n = 0; n < 2000; ++n) {
      LightEmission e;
      ASSERT_TRUE(c.light->sample_le({rng.next_float(), rng.next_float()}, {rng.next_float(), rng.next_float()}, e));
      const Vec3 from_disk_center = e.p - (center - e.dir * radius);
      EXPECT_NEAR(dot(from_disk_center, e.dir), 0.f, 1e-5f * radius) << c.name;  // in the disk's plane
      EXPECT_LE(length(from_disk_center), radius * (1.f + 1e-5f)) << c.name;
      EXPECT_EQ(e.n, e.dir) << c.name;
      EXPECT_NEAR(e.pdf_pos, 1.0 / (test::kEmPi * radius * radius), 1e-6 / (radius * radius)) << c.name;
    }
  }
}

TEST(EmissionSampling, DirectionalIsADelta) {
  auto light = make_directional_light(Vec3(1.f, -2.f, 0.5f), Rgb(0.5f, 1.f, 2.f));
  light->preprocess(test::emission_scene_bounds());
  LightEmission e;
  ASSERT_TRUE(light->sample_le({0.2f, 0.9f}, {0.6f, 0.1f}, e));
  const Vec3 dir = normalize(Vec3(1.f, -2.f, 0.5f));
  EXPECT_NEAR(dot(e.dir, dir), 1.f, 1e-6f);
  EXPECT_EQ(e.pdf_dir, 1.f);
  EXPECT_EQ(e.le, Rgb(0.5f, 1.f, 2.f));
  // sample_li looks back along the same line.
  LightSample ls;
  ASSERT_TRUE(light->sample_li(Vec3(0.f), {0.5f, 0.5f}, ls));
  EXPECT_NEAR(dot(ls.wi, -e.dir), 1.f, 1e-6f);
}

TEST(EmissionSampling, EnvmapDensityIsSampleLisOfTheOppositeDirection) {
  test::EmitterShapes shapes;
  for (const EmitterCase& c : test::make_emitter_cases(shapes)) {
    if (c.kind != EmitterKind::Distant) continue;
    Pcg32 rng(9);
    for (int n = 0; n < 5000; ++n) {
      LightEmission e;
      ASSERT_TRUE(c.light->sample_le({rng.next_float(), rng.next_float()}, {rng.next_float(), rng.next_float()}, e));
      EXPECT_EQ(e.pdf_dir, c.light->pdf_env(-e.dir)) << c.name;
      EXPECT_EQ(e.le, c.light->le_env(-e.dir)) << c.name;
      // Any direction, not only sampled ones.
      const Vec3 d = normalize(Vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f));
      float pdf_pos = 0.f, pdf_dir = 0.f;
      c.light->pdf_le(Vec3(0.f), Vec3(0.f), d, pdf_pos, pdf_dir);
      EXPECT_EQ(pdf_dir, c.light->pdf_env(-d)) << c.name;
    }
  }
}

}  // namespace
}  // namespace tessera
