// thinlens sensor: rays through the focus plane, the factory, and depth of field measured on a
// render (a point in the focus plane stays sharp; off it, the blur disk has the thin-lens radius).
#include "scene_builders.h"
#include "tessera/core/hash.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace tessera {
namespace {

using namespace tessera::test;

constexpr double kPiD = 3.14159265358979323846;

Transform oblique_camera() { return *Transform::look_at({1.f, 2.f, 3.f}, {2.f, 2.5f, 8.f}, {0.f, 1.f, 0.f}); }

TEST(ThinLensCamera, ZeroApertureIsThePinhole) {
  const Transform xf = oblique_camera();
  auto pinhole = make_perspective_camera(xf, 50.f, 120, 80, 0.1f, 500.f);
  auto lens = make_thinlens_camera(xf, 50.f, 120, 80, 0.1f, 500.f, 0.f, 3.f);
  Pcg32 rng(3);
  for (int i = 0; i < 200; ++i) {
    Vec2 raster(120.f * rng.next_float(), 80.f * rng.next_float()), u(rng.next_float(), rng.next_float());
    Ray a = pinhole->generate_ray(raster, u), b = lens->generate_ray(raster, u);
    EXPECT_NEAR(length(a.o - b.o), 0.f, 1e-5f);
    EXPECT_NEAR(length(a.d - b.d), 0.f, 1e-5f);
    EXPECT_NEAR(a.tmin, b.tmin, 1e-5f * a.tmin);
    EXPECT_NEAR(a.tmax, b.tmax, 1e-5f * a.tmax);
  }
}

// Every lens sample of a raster position meets the pinhole ray's point on the focus plane; the
// origins fill the aperture disk uniformly (half of them within radius A / sqrt 2).
TEST(ThinLensCamera, RaysMeetOnTheFocusPlane) {
  const Transform xf = oblique_camera(), cam_from_world = xf.inverse();
  const float aperture = 0.3f, focus = 4.f, near_clip = 0.05f;
  auto pinhole = make_perspective_camera(xf, 35.f, 96, 64, near_clip, 1e3f);
  auto lens = make_thinlens_camera(xf, 35.f, 96, 64, near_clip, 1e3f, aperture, focus);
  Pcg32 rng(11);
  int inner = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    Vec2 raster(96.f * rng.next_float(), 64.f * rng.next_float()), u(rng.next_float(), rng.next_float());
    Ray r = lens->generate_ray(raster, u);
    ASSERT_NEAR(length(r.d), 1.f, 1e-5f);
    Vec3 o = cam_from_world.apply_point(r.o), d = cam_from_world.apply_vector(r.d);
    ASSERT_NEAR(o.z, 0.f, 1e-5f);
    float rho = std::hypot(o.x, o.y);
    ASSERT_LE(rho, aperture * 1.0001f);
    if (rho < aperture / std::sqrt(2.f)) ++inner;
    // Ray starts on the near plane and ends on the far plane (camera z), as Mitsuba's.
    EXPECT_NEAR(o.z + d.z * r.tmin, near_clip, 1e-5f);
    EXPECT_NEAR((o.z + d.z * r.tmax) / 1e3f, 1.f, 1e-4f);
    Vec3 q = o + d * ((focus - o.z) / d.z);
    Vec3 dp = cam_from_world.apply_vector(pinhole->generate_ray(raster, u).d);
    Vec3 p = dp * (focus / dp.z);
    ASSERT_NEAR(length(q - p), 0.f, 2e-5f * focus) << "raster " << raster.x << "," << raster.y;
  }
  EXPECT_NEAR(double(inner) / n, 0.5, 4 * 0.5 / std::sqrt(double(n)));
  // The lens centre gives the pinhole ray.
  Ray c = lens->generate_ray({10.f, 20.f}, {0.5f, 0.5f}), p = pinhole->generate_ray({10.f, 20.f}, {});
  EXPECT_NEAR(length(c.o - p.o), 0.f, 1e-6f);
  EXPECT_NEAR(length(c.d - p.d), 0.f, 1e-6f);
}

std::unique_ptr<Scene> load(const std::string& sensor) {
  LoadOptions o;
  auto desc = parse_scene_string("<scene version=\"0.6.0\">" + sensor + "<shape type=\"sphere\"/></scene>", "mem/cam.xml");
  return load_scene(desc, o).scene;
}

TEST(ThinLensCamera, FactoryReadsMitsubaParameters) {
  const std::string film = R"(<film type="hdrfilm"><integer name="width" value="64"/><integer name="height" value="32"/></film>)";
  auto scene = load(R"(<sensor type="thinlens"><float name="apertureRadius" value="0.2"/><float name="focusDistance" value="4"/>
      <float name="fov" value="40"/><float name="nearClip" value="0.5"/><float name="farClip" value="90"/>
      <transform name="toWorld"><lookat origin="1,2,3" target="2,2.5,8" up="0,1,0"/></transform>)" + film + "</sensor>");
  auto expected = make_thinlens_camera(oblique_camera(), 40.f, 64, 32, 0.5f, 90.f, 0.2f, 4.f);
  // Without focusDistance the focus plane is at farClip (Mitsuba 0.6's ProjectiveCamera).
  auto far_focus = load(R"(<sensor type="thinlens"><float name="apertureRadius" value="0.2"/><float name="fov" value="40"/>
      <float name="farClip" value="90"/>)" + film + "</sensor>");
  auto expected_far = make_thinlens_camera(Transform(), 40.f, 64, 32, 0.01f, 90.f, 0.2f, 90.f);
  Pcg32 rng(2);
  for (int i = 0; i < 50; ++i) {
    Vec2 raster(64.f * rng.next_float(), 32.f * rng.next_float()), u(rng.next_float(), rng.next_float());
    for (auto [got, want] : {std::pair{scene->camera.get(), expected.get()}, {far_focus->camera.get(), expected_far.get()}}) {
      Ray a = got->generate_ray(raster, u), b = want->generate_ray(raster, u);
      EXPECT_NEAR(length(a.o - b.o), 0.f, 1e-5f);
      EXPECT_NEAR(length(a.d - b.d), 0.f, 1e-5f);
      EXPECT_NEAR(a.tmin, b.tmin, 1e-5f);
    }
  }
  // Mitsuba requires the aperture radius.
  EXPECT_THROW(load(R"(<sensor type="thinlens"><float name="focusDistance" value="4"/></sensor>)"), SceneError);
  EXPECT_THROW(load(R"(<sensor type="thinlens"><float name="apertureRadius" value="-1"/></sensor>)"), SceneError);
}

// -- depth of field, measured on renders --

// A 41 x 41 film whose z = 1 image plane has kScale pixels per unit; camera at the origin looking
// down +z; lens radius 1, focus plane z = 5. A small emitting sphere on the axis at depth d.
constexpr int kSize = 41;
constexpr double kScale = 120.0, kAperture = 1.0, kFocus = 5.0;

struct Moments {
  double total = 0, cx = 0, cy = 0, m2 = 0, centre_fraction = 0, max_r = 0;
};

Moments render_point(double depth, double radius_px, int spp) {
  Scene scene;
  // Sphere radius whose silhouette, seen from the lens centre, has radius `radius_px` pixels.
  double t = radius_px / kScale, s = depth * t / std::sqrt(1 + t * t);
  Shape* sphere = add_sphere(scene, Vec3(0.f, 0.f, float(depth)), float(s), false, add_diffuse(scene, Rgb(0.f)));
  add_area_light(scene, *sphere, Rgb(1.f));
  float fov = float(2.0 * std::atan(kSize / (2.0 * kScale)) * 180.0 / kPiD);
  scene.camera = make_thinlens_camera(Transform(), fov, kSize, kSize, 1e-3f, 1e4f, float(kAperture), float(kFocus));
  scene.film.width = scene.film.height = kSize;
  scene.film.filter = make_box_filter(0.5f);  // the pixel footprint only
  scene.sampler.type = SamplerType::Independent;
  scene.integrator.max_depth = 1;  // emitters seen directly
  scene.finalize();
  RenderSettings rs;
  rs.spp = spp;
  rs.seed = 7;
  rs.threads = 2;
  Film film = render(scene, rs);
  Moments m;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      double v = film.mean({x, y}).g;
      m.total += v;
      m.cx += v * (x + 0.5);
      m.cy += v * (y + 0.5);
    }
  m.cx /= m.total;
  m.cy /= m.total;
  const double c = kSize / 2.0;  // the axis: centre of pixel (20, 20)
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      double v = film.mean({x, y}).g, dx = x + 0.5 - c, dy = y + 0.5 - c;
      m.m2 += v * (dx * dx + dy * dy);
      if (v > 0) m.max_r = std::max(m.max_r, std::sqrt(dx * dx + dy * dy));
    }
  m.m2 /= m.total;
  m.centre_fraction = film.mean({kSize / 2, kSize / 2}).g / m.total;
  return m;
}

// E[1/cos alpha] over the lens for a point at depth d on the axis, alpha the angle between the
// axis and the line from a lens point to it (see BlurDiskMatchesThinLensFormula).
double obliquity(double depth) {
  double q = kAperture * kAperture / (depth * depth);
  return 2.0 / (3.0 * q) * (std::pow(1.0 + q, 1.5) - 1.0);
}

// In the focus plane, a point 0.3 pixel in radius centred on a pixel puts (nearly) all its energy in
// that pixel although the lens (radius 1 at distance 5) is wide open.
TEST(ThinLensCamera, PointInFocusPlaneStaysSharp) {
  const int spp = 1024;
  Moments m = render_point(kFocus, 0.3, spp);
  std::printf("[ dof      ] in focus: %.4f of the energy in the centre pixel, total %.4f (pi 0.3^2 = %.4f)\n",
              m.centre_fraction, m.total, kPiD * 0.09);
  EXPECT_GT(m.centre_fraction, 0.97) << "m2 " << m.m2;
  EXPECT_LT(m.max_r, 1.5);
  // Energy: the silhouette's area, pi 0.3^2 pixels (times the obliquity, 1%) at radiance 1; a
  // sample hits it with that probability, so the total is binomial: 4 standard deviations.
  const double p = kPiD * 0.09 * obliquity(kFocus);
  EXPECT_NEAR(m.total, p, 4 * std::sqrt(p * (1 - p) / spp));
}

// Off the focus plane, a point at depth d spreads over a disk of radius
//   R = A |d - f| / (d f) * kScale  pixels
// (the circle of confusion of diameter 2A |d - f| / d on the focus plane, projected through the
// field of view). The image is that uniform disk convolved with the sphere's own silhouette (radius
// rho), so its second moment about the axis is R^2/2 + rho^2/2; measuring at pixel centres the
// box-filtered image takes away 1/12 per axis. Tolerance on R: 2%. Monte Carlo noise on the
// measured R, from the ~10^4 samples that hit, is about 0.5%; the silhouette approximation (a flat
// disk of the same angular radius seen from every lens point) moves R^2 by under 0.5%. A lens
// sampled on a square, or a ray aimed through the wrong focus point, misses by over 10%.
TEST(ThinLensCamera, BlurDiskMatchesThinLensFormula) {
  const double rho = 2.0;
  for (double depth : {10.0, 3.5}) {
    Moments m = render_point(depth, rho, 1024);
    double r_expected = kAperture * std::abs(depth - kFocus) / (depth * kFocus) * kScale;
    double r_measured = std::sqrt(2.0 * (m.m2 - rho * rho / 2.0 + 1.0 / 6.0));
    EXPECT_NEAR(r_measured, r_expected, 0.02 * r_expected) << "depth " << depth;
    // Support: nothing beyond the disk plus the silhouette and one pixel diagonal.
    EXPECT_LE(m.max_r, r_expected + rho + 0.75) << "depth " << depth;
    EXPECT_NEAR(m.cx, kSize / 2.0, 0.2);
    EXPECT_NEAR(m.cy, kSize / 2.0, 0.2);
    // The lens moves energy, it does not create or lose it: the total is the silhouette's area on
    // the film, pi rho^2 from the lens centre and larger by 1/cos(alpha) seen from a lens point at
    // angle alpha off the axis (the ball's cross-section meets the z = d plane obliquely); over the
    // lens, E[1/cos alpha] = 2 d^2 / (3 A^2) ((1 + A^2/d^2)^1.5 - 1) (2% at d = 3.5). Tolerance 3%:
    // ~12,000 hits give 0.9% noise.
    double oblique = obliquity(depth);
    std::printf("[ dof      ] depth %.1f: blur radius %.3f px measured, %.3f thin-lens formula; energy %.3f, expected %.3f\n",
                depth, r_measured, r_expected, m.total, kPiD * rho * rho * oblique);
    EXPECT_NEAR(m.total, kPiD * rho * rho * oblique, 0.03 * kPiD * rho * rho * oblique) << "depth " << depth;
    EXPECT_LT(m.centre_fraction, 0.05);
  }
}

}  // namespace
}  // namespace tessera
