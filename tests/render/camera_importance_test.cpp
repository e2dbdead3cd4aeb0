// Camera importance for light tracing and BDPT (pbrt-v4's PerspectiveCamera We, PDF_We, SampleWi)
// on the pinhole and thin lens cameras, with and without a uniform scale in to_world, and on an
// animated camera: We integrates to 1 over the film, and we()/sample_wi() invert generate_ray().
#include "tessera/core/hash.h"
#include "tessera/core/rgb.h"  // camera.h uses Rgb without including it
#include "tessera/render/camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace tessera {
namespace {

constexpr int kWidth = 96, kHeight = 64;
constexpr float kFov = 50.f, kNear = 0.1f, kFar = 500.f, kAperture = 0.3f, kFocus = 4.f;

struct CamCase {
  std::string name;
  Transform world_from_camera;
  float scale = 1.f;     // uniform scale inside world_from_camera
  float aperture = 0.f;  // camera units
  std::unique_ptr<Camera> cam;
  // The lens area in world units, 1 for a pinhole (pbrt's convention).
  float lens_area() const { return aperture > 0.f ? kPi * (scale * aperture) * (scale * aperture) : 1.f; }
  Vec3 forward() const { return normalize(world_from_camera.apply_vector({0.f, 0.f, 1.f})); }
};

Transform oblique_camera() { return *Transform::look_at({1.f, 2.f, 3.f}, {2.f, 2.5f, 8.f}, {0.f, 1.f, 0.f}); }

CamCase make_case(const std::string& name, float scale, float aperture) {
  CamCase c{name, oblique_camera() * Transform::scale(Vec3(scale)), scale, aperture, nullptr};
  const Transform& xf = c.world_from_camera;
  c.cam = aperture > 0.f ? make_thinlens_camera(xf, kFov, kWidth, kHeight, kNear, kFar, aperture, kFocus)
                         : make_perspective_camera(xf, kFov, kWidth, kHeight, kNear, kFar);
  return c;
}

std::vector<CamCase> all_cases() {
  std::vector<CamCase> v;
  v.push_back(make_case("pinhole", 1.f, 0.f));
  v.push_back(make_case("thinlens", 1.f, kAperture));
  v.push_back(make_case("pinhole scaled", 2.f, 0.f));
  v.push_back(make_case("thinlens scaled", 2.f, kAperture));
  return v;
}

// Area of the whole film's image on the camera-space plane z = 1.
double film_area() {
  const double tx = std::tan(kFov * M_PI / 360.0);
  return 4.0 * tx * tx * kHeight / kWidth;
}

float distance_to_line(Vec3 p, const Ray& r) { return length(cross(p - r.o, r.d)); }

// Monte Carlo of the integral of We cos over the lens (world area) and directions, which must be 1;
// and of pdf_dir over directions, also 1. Directions are drawn uniformly in a cone around the axis
// wider than the film, so the off-film zeros are exercised too.
TEST(CameraImportance, WeIntegratesToOneOverFilm) {
  const double cos_max = std::cos(45.0 * M_PI / 180.0), cone_pdf = 1.0 / (2 * M_PI * (1 - cos_max));
  for (const CamCase& c : all_cases()) {
    Pcg32 rng(5);
    const int n = 400000;
    double sum = 0, sum2 = 0, pdf_sum = 0;
    for (int i = 0; i < n; ++i) {
      // generate_ray's origin is a uniform lens point (any raster will do).
      Vec3 o = c.cam->generate_ray({48.f, 32.f}, {rng.next_float(), rng.next_float()}).o;
      double z = 1 - rng.next_float() * (1 - cos_max), phi = 2 * M_PI * rng.next_float(), s = std::sqrt(1 - z * z);
      Vec3 d_cam(float(s * std::cos(phi)), float(s * std::sin(phi)), float(z));
      Ray ray{o, normalize(c.world_from_camera.apply_vector(d_cam))};
      double v = double(c.cam->we(ray, nullptr).g) * z * c.lens_area() / cone_pdf;
      sum += v;
      sum2 += v * v;
      float pdf_pos, pdf_dir;
      c.cam->pdf_we(ray, pdf_pos, pdf_dir);
      pdf_sum += pdf_dir / cone_pdf;
      if (pdf_dir > 0.f) {
        ASSERT_NEAR(pdf_pos * c.lens_area(), 1.f, 1e-5f) << c.name;
      }
    }
    const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, 1.0, 4 * se) << c.name << " (standard error " << se << ")";
    EXPECT_LT(se, 0.01) << c.name;
    // pdf_dir is We cos times the lens area: the same estimator, the same tolerance.
    EXPECT_NEAR(pdf_sum / n, 1.0, 4 * se) << c.name;
  }
}

TEST(CameraImportance, WeOfGeneratedRayGivesItsRaster) {
  for (const CamCase& c : all_cases()) {
    EXPECT_TRUE(c.cam->has_importance()) << c.name;
    Pcg32 rng(7);
    for (int i = 0; i < 500; ++i) {
      Vec2 raster(kWidth * rng.next_float(), kHeight * rng.next_float()), u(rng.next_float(), rng.next_float());
      Ray ray = c.cam->generate_ray(raster, u);
      Vec2 back(-1.f, -1.f);
      Rgb we = c.cam->we(ray, &back);
      ASSERT_NEAR(back.x, raster.x, 2e-3f) << c.name;
      ASSERT_NEAR(back.y, raster.y, 2e-3f) << c.name;
      // Off the lens axis the importance follows cos^-4 of the angle to the viewing direction.
      const double cos_t = dot(ray.d, c.forward());
      const double expected = 1.0 / (film_area() * c.lens_area() * std::pow(cos_t, 4));
      ASSERT_NEAR(we.r / expected, 1.0, 1e-4) << c.name;
      EXPECT_EQ(we.r, we.b);
      float pdf_pos, pdf_dir;
      c.cam->pdf_we(ray, pdf_pos, pdf_dir);
      ASSERT_NEAR(pdf_dir * film_area() * std::pow(cos_t, 3), 1.0, 1e-4) << c.name;
      // Backwards: nothing.
      EXPECT_EQ(c.cam->we(Ray{ray.o, -ray.d}, nullptr).r, 0.f) << c.name;
    }
    // A ray well outside the field of view misses the film.
    Ray off{c.cam->generate_ray({48.f, 32.f}, {0.5f, 0.5f}).o,
            normalize(c.world_from_camera.apply_vector({1.f, 0.f, 1.f}))};
    EXPECT_EQ(c.cam->we(off, nullptr).r, 0.f) << c.name;
    float pdf_pos = 1, pdf_dir = 1;
    c.cam->pdf_we(off, pdf_pos, pdf_dir);
    EXPECT_EQ(pdf_dir, 0.f) << c.name;
  }
}

// sample_wi must find the raster whose generate_ray (same u_lens) passes through ref_p, and report
// a lens point, direction and pdf consistent with pdf_we.
void check_sample_wi(const CamCase& c, Vec3 ref_p, Vec2 u, const CameraSampleWi& s) {
  Ray ray = c.cam->generate_ray_at(s.raster, u, 0.f);
  const float dist = length(ref_p - ray.o);
  ASSERT_LT(distance_to_line(ref_p, ray), 2e-5f * dist) << c.name;
  const float t = dot(ref_p - ray.o, ray.d);
  EXPECT_GE(t, ray.tmin * (1 - 1e-4f)) << c.name;
  EXPECT_LE(t, ray.tmax * (1 + 1e-4f)) << c.name;
  EXPECT_LT(length(s.p_lens - ray.o), 1e-5f * c.scale) << c.name;
  EXPECT_NEAR(s.dist, dist, 1e-5f * dist) << c.name;
  EXPECT_LT(length(s.wi - normalize(s.p_lens - ref_p)), 1e-5f) << c.name;
  EXPECT_LT(length(s.n - c.forward()), 1e-5f) << c.name;
  // The position density converted to solid angle at ref_p (pbrt: dist^2 / (|cos| lens area)).
  const Ray back{s.p_lens, -s.wi};
  float pdf_pos, pdf_dir;
  c.cam->pdf_we(back, pdf_pos, pdf_dir);
  const float cos_lens = std::abs(dot(s.n, s.wi));
  EXPECT_NEAR(s.pdf / (pdf_pos * s.dist * s.dist / cos_lens), 1.f, 1e-4f) << c.name;
  Vec2 r;
  EXPECT_NEAR(s.we.r / c.cam->we(back, &r).r, 1.f, 1e-3f) << c.name;
  EXPECT_NEAR(r.x, s.raster.x, 2e-3f) << c.name;
  EXPECT_NEAR(r.y, s.raster.y, 2e-3f) << c.name;
}

TEST(CameraImportance, SampleWiInvertsGenerateRay) {
  for (const CamCase& c : all_cases()) {
    Pcg32 rng(9);
    for (int i = 0; i < 500; ++i) {
      // A point on a generated ray, at a log-uniform distance, must map back to that ray's raster.
      Vec2 raster(kWidth * rng.next_float(), kHeight * rng.next_float()), u(rng.next_float(), rng.next_float());
      Ray ray = c.cam->generate_ray(raster, u);
      const float t = ray.tmin * std::pow(std::min(ray.tmax, 100.f * c.scale) / ray.tmin, rng.next_float());
      const Vec3 ref_p = ray.at(t);
      CameraSampleWi s;
      ASSERT_TRUE(c.cam->sample_wi(ref_p, u, 0.f, s)) << c.name << " t " << t;
      EXPECT_NEAR(s.raster.x, raster.x, 2e-3f) << c.name << " t " << t;
      EXPECT_NEAR(s.raster.y, raster.y, 2e-3f) << c.name << " t " << t;
      check_sample_wi(c, ref_p, u, s);
    }
    // Arbitrary points around the camera: those seen must satisfy the same contract.
    int seen = 0;
    for (int i = 0; i < 500; ++i) {
      Vec3 p_cam(10 * rng.next_float() - 5, 10 * rng.next_float() - 5, 12 * rng.next_float() - 2);
      Vec2 u(rng.next_float(), rng.next_float());
      CameraSampleWi s;
      if (!c.cam->sample_wi(c.world_from_camera.apply_point(p_cam), u, 0.f, s)) continue;
      ++seen;
      check_sample_wi(c, c.world_from_camera.apply_point(p_cam), u, s);
    }
    EXPECT_GT(seen, 50) << c.name;
  }
}

TEST(CameraImportance, SampleWiRejectsUnseenPoints) {
  for (const CamCase& c : all_cases()) {
    // The lens centre: off it, a point this near the lens is seen through a raster far off axis.
    auto seen = [&](Vec3 p_cam, Vec2 u = {0.5f, 0.5f}) {
      CameraSampleWi s;
      return c.cam->sample_wi(c.world_from_camera.apply_point(p_cam), u, 0.f, s);
    };
    EXPECT_TRUE(seen({0.f, 0.f, 2.f})) << c.name;
    EXPECT_TRUE(seen({0.f, 0.f, 2.f}, {0.3f, 0.6f})) << c.name;
    EXPECT_FALSE(seen({0.f, 0.f, -2.f})) << c.name << ": behind";
    EXPECT_FALSE(seen({3.f, 0.f, 2.f})) << c.name << ": off film (x)";
    EXPECT_FALSE(seen({0.f, -2.f, 2.f})) << c.name << ": off film (y)";
    // The clip planes are camera-space depths (generate_ray's rays span z in [near, far]).
    EXPECT_FALSE(seen({0.f, 0.f, 0.5f * kNear})) << c.name << ": nearer than the near clip";
    EXPECT_TRUE(seen({0.f, 0.f, 1.5f * kNear})) << c.name;
    EXPECT_FALSE(seen({0.f, 0.f, 1.1f * kFar})) << c.name << ": beyond the far clip";
  }
}

TEST(CameraImportance, OrthographicHasNoImportance) {
  auto ortho = make_orthographic_camera(oblique_camera(), kWidth, kHeight, kNear, kFar);
  EXPECT_FALSE(ortho->has_importance());
  auto moving = make_animated_camera(make_orthographic_camera(oblique_camera(), kWidth, kHeight, kNear, kFar),
                                     oblique_camera(), AnimatedTransform(oblique_camera()));
  EXPECT_FALSE(moving->has_importance());
}

// A thin lens camera turning and sliding over the shutter: at each time, sample_wi answers as the
// camera at that time's transform does, and we() undoes generate_ray_at at the ray's time.
TEST(CameraImportance, AnimatedCameraFollowsMotion) {
  const Transform w0 = oblique_camera();
  const Transform w1 = Transform::translate({0.4f, -0.2f, 0.3f}) * w0 * Transform::rotate({0.f, 1.f, 0.f}, 6.f);
  auto make = [](const Transform& xf) {
    return make_thinlens_camera(xf, kFov, kWidth, kHeight, kNear, kFar, kAperture, kFocus);
  };
  auto cam = make_animated_camera(make(w0), w0, AnimatedTransform({{0.f, w0}, {1.f, w1}}));
  ASSERT_TRUE(cam->has_importance());
  auto at_end = make(w1);
  const Vec3 ref_p = w0.apply_point({0.3f, -0.2f, 5.f});
  const Vec2 u(0.7f, 0.2f);
  Vec2 rasters[3];
  const float times[3] = {0.f, 0.5f, 1.f};
  for (int k = 0; k < 3; ++k) {
    CameraSampleWi s;
    ASSERT_TRUE(cam->sample_wi(ref_p, u, times[k], s)) << "time " << times[k];
    rasters[k] = s.raster;
    Ray ray = cam->generate_ray_at(s.raster, u, times[k]);
    EXPECT_LT(distance_to_line(ref_p, ray), 2e-5f * length(ref_p - ray.o)) << "time " << times[k];
    EXPECT_LT(length(s.p_lens - ray.o), 1e-5f) << "time " << times[k];
    EXPECT_LT(length(s.wi - normalize(s.p_lens - ref_p)), 1e-5f);
    EXPECT_LT(length(s.n - normalize(cam->generate_ray_at({48.f, 32.f}, {0.5f, 0.5f}, times[k]).d)), 1e-5f);
    Vec2 back;
    EXPECT_GT(cam->we(ray, &back).r, 0.f);
    EXPECT_NEAR(back.x, s.raster.x, 2e-3f) << "time " << times[k];
    EXPECT_NEAR(back.y, s.raster.y, 2e-3f) << "time " << times[k];
    float pdf_pos, pdf_dir;
    cam->pdf_we(ray, pdf_pos, pdf_dir);
    EXPECT_GT(pdf_dir, 0.f);
  }
  EXPECT_GT(length(Vec3(rasters[2].x - rasters[0].x, rasters[2].y - rasters[0].y, 0.f)), 2.f);
  // At the closing keyframe the animated camera is the camera built at w1.
  CameraSampleWi s1;
  ASSERT_TRUE(at_end->sample_wi(ref_p, u, 0.f, s1));
  EXPECT_NEAR(s1.raster.x, rasters[2].x, 2e-3f);
  EXPECT_NEAR(s1.raster.y, rasters[2].y, 2e-3f);
}

}  // namespace
}  // namespace tessera
