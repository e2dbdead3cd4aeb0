// Lights at their limits: a tiny, very bright light (veach-bidir's radiance of 12,048), lights behind the
// camera, a camera inside a closed object, an environment map with a single bright texel, and light
// grazing a large plane at 89 degrees.
//
// The yardstick is irradiance in closed form on a one-sided diffuse plane of albedo rho: its
// radiance is rho / pi * E, with E = pi L (r / D)^2 cos(theta) for a sphere of radius r entirely above
// the horizon (D, theta: distance and angle to its centre), Lambert's contour formula for a polygon,
// E cos(theta) for a directional light. Each pixel's expectation is that radiance averaged over an
// 8 x 8 grid of camera rays inside the pixel (the film uses a box filter), computed in double.
#include "hardcases/hardcase_support.h"
#include "render/scene_builders.h"
#include "test_support.h"
#include "tessera/light/constant.h"
#include "tessera/light/directional.h"
#include "tessera/light/envmap.h"
#include "tessera/render/integrator.h"

#include <cstdio>
#include <functional>

namespace tessera {
namespace {

constexpr double kPi64 = 3.14159265358979323846;

struct D3 {
  double x, y, z;
};
D3 d3(Vec3 v) { return {v.x, v.y, v.z}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
D3 unit(D3 a) {
  const double l = std::sqrt(dot(a, a));
  return {a.x / l, a.y / l, a.z / l};
}

/// Irradiance at `p` (normal `n`) from a sphere of radiance `L` entirely above p's horizon.
double sphere_irradiance(Vec3 p, Vec3 n, Vec3 c, double r, double L) {
  const D3 d = d3(c) - d3(p);
  const double dist2 = dot(d, d);
  return kPi64 * L * r * r / dist2 * dot(d3(n), d) / std::sqrt(dist2);
}

/// Irradiance at `p` (normal `n`) from a planar polygon of radiance `L` entirely above p's horizon
/// (Lambert: E = L / 2 * sum over edges of angle * n . unit(v_i x v_i+1), with v unit vectors).
double polygon_irradiance(Vec3 p, Vec3 n, const std::vector<Vec3>& poly, double L) {
  double sum = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const D3 a = unit(d3(poly[i]) - d3(p)), b = unit(d3(poly[(i + 1) % poly.size()]) - d3(p));
    const double angle = std::acos(std::clamp(dot(a, b), -1.0, 1.0));
    sum += angle * dot(d3(n), unit(cross(a, b)));
  }
  return 0.5 * L * std::abs(sum);
}

using RadianceAt = std::function<double(const SurfaceInteraction&)>;

/// Per-pixel expectation: `radiance` at the first hit, averaged over 8 x 8 rays per pixel (0 for
/// rays that hit nothing).
std::vector<double> expected_pixels(const Scene& scene, const RadianceAt& radiance) {
  std::vector<double> out;
  for (int y = 0; y < scene.film.height; ++y)
    for (int x = 0; x < scene.film.width; ++x) {
      double sum = 0;
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          SurfaceInteraction si;
          const Ray ray = scene.camera->generate_ray(Vec2(x + (i + 0.5f) / 8.f, y + (j + 0.5f) / 8.f), {});
          if (scene.intersect(ray, si)) sum += radiance(si);
        }
      out.push_back(sum / 64);
    }
  return out;
}

struct Agreement {
  double mean_ratio = 0;       // image mean / expected image mean
  double mean_z = 0;           // (image mean - expected) / its standard error
  double worst_rel = 0;        // largest |pixel - expected| / expected
  double worst_z = 0;          // largest |pixel - expected| / pixel standard error
  double rel_std = 0;          // standard deviation of pixel / expected over the image
  int n = 0;
};

/// Green channel of `film` against `expected` over the pixels `use` accepts.
Agreement compare(const Film& film, const std::vector<double>& expected,
                  const std::function<bool(int, int)>& use = [](int, int) { return true; }) {
  Agreement a;
  double sum = 0, sum_exp = 0, var = 0, sum_r = 0, sum_r2 = 0;
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      if (!use(x, y)) continue;
      const double e = expected[size_t(y) * size_t(film.width()) + size_t(x)];
      const double v = film.mean({x, y}).g;
      const double se2 = double(film.sample_variance({x, y}).g) / double(film.pixel({x, y}).count);
      sum += v;
      sum_exp += e;
      var += se2;
      a.worst_rel = std::max(a.worst_rel, std::abs(v - e) / e);
      a.worst_z = std::max(a.worst_z, std::abs(v - e) / std::sqrt(se2 + 1e-30));
      sum_r += v / e;
      sum_r2 += (v / e) * (v / e);
      ++a.n;
    }
  a.mean_ratio = sum / sum_exp;
  a.mean_z = (sum - sum_exp) / std::sqrt(var + 1e-30);
  a.rel_std = std::sqrt(std::max(sum_r2 / a.n - (sum_r / a.n) * (sum_r / a.n), 0.0));
  return a;
}

void print(const char* what, const Agreement& a) {
  std::printf("%-34s %4d px: mean ratio %.5f (z %.2f), worst pixel %.4f rel (z %.2f), rel std %.2e\n", what, a.n,
              a.mean_ratio, a.mean_z, a.worst_rel, a.worst_z, a.rel_std);
}

/// The quad [x0, x1] x [z0, z1] at height y facing +y (or -y when `down`).
std::shared_ptr<MeshData> quad_y(float x0, float x1, float z0, float z1, float y, bool down) {
  auto m = std::make_shared<MeshData>();
  m->positions = {{x0, y, z0}, {x1, y, z0}, {x1, y, z1}, {x0, y, z1}};
  m->indices = down ? std::vector<uint32_t>{0, 1, 2, 0, 2, 3} : std::vector<uint32_t>{0, 2, 1, 0, 3, 2};
  return m;
}

Shape* add_mesh(Scene& scene, std::shared_ptr<MeshData> mesh, const Bsdf* bsdf) {
  scene.shapes.push_back(std::make_unique<TriangleMeshShape>(std::move(mesh), false, false));
  scene.shapes.back()->bsdf = bsdf;
  return scene.shapes.back().get();
}

/// Orthographic camera at height `h` looking down -y at [-half, half]^2 of the plane y = 0.
void set_camera_down(Scene& scene, float h, float half, int size) {
  const Transform look = *Transform::look_at({0.f, h, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 1.f});
  scene.camera = make_orthographic_camera(look * Transform::scale({half, half, 1.f}), size, size, 1e-3f, 1e4f);
  scene.film.width = scene.film.height = size;
  scene.film.filter = make_box_filter(0.5f);
}

constexpr float kVeachRadiance = 12048.f;  // veach-bidir's small lamp (red channel)
constexpr float kAlbedo = 0.5f;

// A sphere of radius 5e-3 with radiance 12,048 one unit above a diffuse plane (0.5), seen from above;
// and a square lamp of side 1e-2 (area 1e-4, as small as veach-bidir's) with the same radiance.
// Expected: each pixel is rho L r^2 h / D^3 (sphere; 0.151 under the lamp) or rho/pi times Lambert's
// polygon irradiance (0.192 under the lamp), within 4 of its standard errors plus 1% (the expectation's
// own 8 x 8 quadrature), the image mean within 0.3%; the four pixels around the lamp's foot,
// where the camera sees the lamp itself, are left out.
TEST(HardLights, TinyVeryBrightLightMatchesAnalyticIrradiance) {
  for (bool sphere : {true, false}) {
    Scene scene;
    const Bsdf* white = test::add_diffuse(scene, Rgb(kAlbedo));
    const Bsdf* black = test::add_diffuse(scene, Rgb(0.f));
    add_mesh(scene, quad_y(-2.f, 2.f, -2.f, 2.f, 0.f, false), white);
    constexpr float kR = 5e-3f, kHalf = 5e-3f;
    const Vec3 c(0.f, 1.f, 0.f);
    Shape* lamp = sphere ? test::add_sphere(scene, c, kR, false, black)
                         : add_mesh(scene, quad_y(-kHalf, kHalf, -kHalf, kHalf, 1.f, true), black);
    test::add_area_light(scene, *lamp, Rgb(kVeachRadiance));
    set_camera_down(scene, 3.f, 1.f, 32);
    scene.finalize();
    const std::vector<Vec3> poly = {{-kHalf, 1.f, -kHalf}, {kHalf, 1.f, -kHalf}, {kHalf, 1.f, kHalf}, {-kHalf, 1.f, kHalf}};
    const auto expected = expected_pixels(scene, [&](const SurfaceInteraction& si) {
      if (si.shape == lamp) return 0.0;
      const double e = sphere ? sphere_irradiance(si.p, si.ng, c, kR, kVeachRadiance)
                              : polygon_irradiance(si.p, si.ng, poly, kVeachRadiance);
      return kAlbedo / kPi64 * e;
    });
    const Film film = test::render_checked(scene, test::hard_settings(16), sphere ? "tiny sphere" : "tiny quad");
    const Agreement a = compare(film, expected, [](int x, int y) { return !((x == 15 || x == 16) && (y == 15 || y == 16)); });
    print(sphere ? "tiny sphere light (r 5e-3)" : "tiny quad light (1e-2 side)", a);
    EXPECT_NEAR(a.mean_ratio, 1.0, 3e-3);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) {
        if ((x == 15 || x == 16) && (y == 15 || y == 16)) continue;
        const double e = expected[size_t(y) * 32 + size_t(x)];
        const double v = film.mean({x, y}).g;
        const double se = std::sqrt(double(film.sample_variance({x, y}).g) / double(film.pixel({x, y}).count));
        EXPECT_NEAR(v, e, 4 * se + 0.01 * e) << (sphere ? "sphere" : "quad") << " pixel " << x << "," << y;
      }
  }
}

// A sphere light (radius 0.2, radiance 50) one unit behind a pinhole camera, and in a second scene a
// square lamp (0.6 x 0.6, radiance 20) half a unit behind it facing forward; the camera looks at a
// diffuse wall 3 units ahead. Expected: the wall is lit as the closed forms say (each pixel within
// 4 standard errors plus 1%, the mean within 0.5%), and no pixel shows the light (that would be
// 50 or 20 against the wall's ~0.1).
TEST(HardLights, LightBehindTheCameraLightsTheSceneUnseen) {
  for (bool sphere : {true, false}) {
    Scene scene;
    const Bsdf* white = test::add_diffuse(scene, Rgb(kAlbedo));
    const Bsdf* black = test::add_diffuse(scene, Rgb(0.f));
    auto wall = std::make_shared<MeshData>();
    wall->positions = {{-5.f, -5.f, 3.f}, {-5.f, 5.f, 3.f}, {5.f, 5.f, 3.f}, {5.f, -5.f, 3.f}};
    wall->indices = {0, 1, 2, 0, 2, 3};  // faces -z, the camera
    add_mesh(scene, wall, white);
    const Vec3 c(0.f, 0.3f, -1.f);
    const std::vector<Vec3> poly = {{-0.1f, -0.4f, -0.5f}, {0.5f, -0.4f, -0.5f}, {0.5f, 0.2f, -0.5f}, {-0.1f, 0.2f, -0.5f}};
    Shape* lamp;
    if (sphere) {
      lamp = test::add_sphere(scene, c, 0.2f, false, black);
      test::add_area_light(scene, *lamp, Rgb(50.f));
    } else {
      auto m = std::make_shared<MeshData>();
      m->positions = poly;
      m->indices = {0, 1, 2, 0, 2, 3};  // counter-clockwise seen from +z: faces the wall
      lamp = add_mesh(scene, m, black);
      test::add_area_light(scene, *lamp, Rgb(20.f));
    }
    test::set_camera(scene, Vec3(0.f), 60.f, 32, 24);
    scene.film.filter = make_box_filter(0.5f);
    scene.finalize();
    const auto expected = expected_pixels(scene, [&](const SurfaceInteraction& si) {
      const double e = sphere ? sphere_irradiance(si.p, si.ng, c, 0.2, 50.0) : polygon_irradiance(si.p, si.ng, poly, 20.0);
      return kAlbedo / kPi64 * e;
    });
    const Film film = test::render_checked(scene, test::hard_settings(16), "light behind camera");
    const Agreement a = compare(film, expected);
    print(sphere ? "sphere light behind the camera" : "quad light behind the camera", a);
    EXPECT_EQ(a.n, 32 * 24);
    EXPECT_NEAR(a.mean_ratio, 1.0, 5e-3);
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 32; ++x) {
        const double e = expected[size_t(y) * 32 + size_t(x)];
        const double v = film.mean({x, y}).g;
        const double se = std::sqrt(double(film.sample_variance({x, y}).g) / double(film.pixel({x, y}).count));
        EXPECT_NEAR(v, e, 4 * se + 0.01 * e) << "pixel " << x << "," << y;
      }
  }
}

/// Mean of the green channel over the image and its standard error (from the film's variances).
std::pair<double, double> image_mean_se(const Film& film) {
  double sum = 0, var = 0;
  const int n = film.width() * film.height();
  for (int y = 0; y < film.height(); ++y)
    for (int x = 0; x < film.width(); ++x) {
      sum += film.mean({x, y}).g;
      var += double(film.sample_variance({x, y}).g) / double(film.pixel({x, y}).count);
    }
  return {sum / n, std::sqrt(var) / n};
}

// A camera inside a closed surface that emits Le = 1 inwards and reflects rho = 0.5 diffusely (an
// integrating sphere; a flipped analytic sphere and an inward-facing mesh cube), with a constant sky
// of 100 outside. Expected: radiance is the same everywhere inside, Le / (1 - rho) = 2 (the image
// mean within 4 standard errors and 0.5%; every pixel within 0.25, far below a leak of the sky).
// Control: inside an ordinary (outward-facing, one-sided) diffuse cube under that sky, the camera
// sees the backs of its faces: every pixel exactly 0.
TEST(HardLights, CameraInsideAClosedObject) {
  for (int variant = 0; variant < 3; ++variant) {
    Scene scene;
    const Bsdf* grey = test::add_diffuse(scene, Rgb(0.5f));
    Shape* shell;
    if (variant == 0) {
      shell = test::add_sphere(scene, Vec3(0.f), 1.f, /*flip=*/true, grey);
    } else {
      shell = add_mesh(scene, test::cube_mesh(1.f, /*inward=*/variant == 1), grey);
    }
    if (variant < 2) test::add_area_light(scene, *shell, Rgb(1.f));
    scene.lights.push_back(std::make_unique<ConstantLight>(Rgb(100.f)));
    test::set_camera(scene, Vec3(0.1f, 0.2f, -0.3f), 70.f, 16, 16);
    scene.film.filter = make_box_filter(0.5f);
    scene.finalize();
    const char* what = variant == 0 ? "inside an emitting sphere" : variant == 1 ? "inside an emitting cube" : "inside a plain cube";
    const Film film = test::render_checked(scene, test::hard_settings(64), what);
    const auto [mean, se] = image_mean_se(film);
    double lo = 1e30, hi = -1e30;
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        for (int c = 0; c < 3; ++c) {
          lo = std::min(lo, double(film.mean({x, y})[c]));
          hi = std::max(hi, double(film.mean({x, y})[c]));
        }
      }
    std::printf("camera %-26s mean %.5f +- %.5f, pixels in [%.4f, %.4f]\n", what, mean, se, lo, hi);
    if (variant < 2) {
      EXPECT_NEAR(mean, 2.0, std::max(4 * se, 1e-3)) << what;
      EXPECT_NEAR(mean, 2.0, 0.01) << what;
      EXPECT_GT(lo, 1.75) << what;
      EXPECT_LT(hi, 2.25) << what;
    } else {
      EXPECT_EQ(lo, 0.0) << what;
      EXPECT_EQ(hi, 0.0) << what;
    }
  }
}

// An environment map of 64 x 32 black texels but one, (20, 10), of radiance 1e4, written to and read
// from an EXR; a diffuse plane (0.5) facing up (+y, the map's pole). With the bilinear texel placement
// of envmap.h the texel's radiance is a tent over one column in u and two row spacings in v, so
// E = V pi^2 sin(2 pi v0) w / W * sinc^2(pi w), v0 = 10/31, w = 1/31 (46.0 for V = 1e4; the same
// within 0.1% from a quadrature of le_env over the sphere), and the plane shows rho/pi E everywhere.
// Expected: with importance sampling (mis, nee) at 16 spp the image mean within 1% of it, the
// relative spread of the pixels below 12% and every pixel within 35% (measured 0.13%, 7.2%, 17%: a
// light sample's weight follows the bilinear tent across its cell); BSDF sampling alone is unbiased
// (mean within 4 standard errors) but at least 5 times noisier per pixel (measured 69 times): the
// texel covers 1e-4 of the sphere, so cosine-sampled rays seldom find it.
TEST(HardLights, EnvmapWithOneBrightTexelIsFoundBySampling) {
  constexpr int kW = 64, kH = 32, kX = 20, kY = 10;
  constexpr double kV = 1e4;
  test::TempDir dir;
  Image map(kW, kH, 3);
  map.set_rgb(kX, kY, Rgb(float(kV)));
  const std::string path = (dir.path / "one_texel.exr").string();
  write_image(path, map);
  const Image loaded = read_image(path);

  const double v0 = double(kY) / (kH - 1), w = 1.0 / (kH - 1);
  const double sinc = std::sin(kPi64 * w) / (kPi64 * w);
  const double e_closed = kV * kPi64 * kPi64 * std::sin(2 * kPi64 * v0) * w / kW * sinc * sinc;
  {
    // Independent check of the closed form: midpoint quadrature of le_env(d) max(d.y, 0) over the sphere.
    EnvmapLight light(loaded, 1.f, Transform());
    constexpr int kNu = 4096, kNv = 2048;
    double e_quad = 0;
    for (int j = 0; j < kNv; ++j) {
      const double theta = kPi64 * (j + 0.5) / kNv;
      if (theta > kPi64 / 2) break;
      for (int i = 0; i < kNu; ++i) {
        const double phi = 2 * kPi64 * (i + 0.5) / kNu;
        const Vec3 d(float(std::sin(phi) * std::sin(theta)), float(std::cos(theta)), float(-std::cos(phi) * std::sin(theta)));
        e_quad += light.le_env(d).g * std::cos(theta) * std::sin(theta) * (kPi64 / kNv) * (2 * kPi64 / kNu);
      }
    }
    std::printf("one-texel envmap: irradiance closed form %.5f, quadrature %.5f\n", e_closed, e_quad);
    ASSERT_NEAR(e_quad / e_closed, 1.0, 1e-3);
  }
  const double expected_radiance = kAlbedo / kPi64 * e_closed;

  double mis_rel_std = 0;
  for (SamplingStrategy strategy : {SamplingStrategy::Mis, SamplingStrategy::Nee, SamplingStrategy::Bsdf}) {
    Scene scene;
    add_mesh(scene, quad_y(-3.f, 3.f, -3.f, 3.f, 0.f, false), test::add_diffuse(scene, Rgb(kAlbedo)));
    scene.lights.push_back(std::make_unique<EnvmapLight>(loaded, 1.f, Transform()));
    set_camera_down(scene, 1.f, 1.f, 16);
    scene.integrator.strategy = strategy;
    scene.finalize();
    const std::vector<double> expected(16 * 16, expected_radiance);
    const std::string what = std::string("one-texel envmap, ") + sampling_strategy_name(strategy);
    const Film film = test::render_checked(scene, test::hard_settings(16), what);
    const Agreement a = compare(film, expected);
    print(what.c_str(), a);
    if (strategy != SamplingStrategy::Bsdf) {
      EXPECT_NEAR(a.mean_ratio, 1.0, 0.01) << what;
      EXPECT_LT(a.rel_std, 0.12) << what;
      EXPECT_LT(a.worst_rel, 0.35) << what;
      mis_rel_std = std::max(mis_rel_std, a.rel_std);
    } else {
      EXPECT_LT(std::abs(a.mean_z), 4.0) << what << ": BSDF sampling alone must still be unbiased";
      EXPECT_GT(a.rel_std, 5 * mis_rel_std) << what;
    }
  }
}

// Light at 89 and 89.9 degrees from the normal of a 2000 x 2000 diffuse plane (0.8), seen from 300
// units above (the view spans 600 x 600 units): a directional light of irradiance 1, and a sphere
// (radius 10, radiance 1e4) 1000 units away at 89 degrees (0.44 degrees across, entirely above the
// horizon). Expected: directional: every sample is exactly rho/pi E cos(theta) (1.1% of rho/pi at
// 89.9 degrees), so every pixel within 1e-3 relative of it and the relative spread across the plane
// below 1e-3: a self-shadowed shadow ray (acne) would take 1/16 off a pixel. Sphere: each pixel
// within 4 standard errors plus 1% of the closed form, the mean within 1%.
TEST(HardLights, GrazingLightOnALargePlane) {
  constexpr float kRho = 0.8f;
  for (float deg : {89.f, 89.9f, -89.f}) {
    const bool sphere = deg < 0;
    const float theta = std::abs(deg) * kPi / 180.f;
    const Vec3 to_light(std::sin(theta), std::cos(theta), 0.f);
    Scene scene;
    add_mesh(scene, quad_y(-1000.f, 1000.f, -1000.f, 1000.f, 0.f, false), test::add_diffuse(scene, Rgb(kRho)));
    const Vec3 c = to_light * 1000.f;
    if (sphere) {
      Shape* sun = test::add_sphere(scene, c, 10.f, false, test::add_diffuse(scene, Rgb(0.f)));
      test::add_area_light(scene, *sun, Rgb(1e4f));
    } else {
      scene.lights.push_back(make_directional_light(-to_light, Rgb(1.f)));
    }
    const Transform look = *Transform::look_at({0.f, 300.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 1.f});
    scene.camera = make_perspective_camera(look, 90.f, 32, 32, 1e-2f, 1e5f);
    scene.film.width = scene.film.height = 32;
    scene.film.filter = make_box_filter(0.5f);
    scene.finalize();
    const double cos_theta = std::cos(double(std::abs(deg)) * kPi64 / 180.0);
    const auto expected = expected_pixels(scene, [&](const SurfaceInteraction& si) {
      return kRho / kPi64 * (sphere ? sphere_irradiance(si.p, si.ng, c, 10.0, 1e4) : cos_theta);
    });
    const std::string what = sphere ? "sphere light at 89 deg" : "directional at " + std::to_string(deg) + " deg";
    const Film film = test::render_checked(scene, test::hard_settings(16), what);
    const Agreement a = compare(film, expected);
    print(what.c_str(), a);
    EXPECT_EQ(a.n, 32 * 32);
    if (!sphere) {
      EXPECT_LT(a.worst_rel, 1e-3) << what;
      EXPECT_LT(a.rel_std, 1e-3) << what;
    } else {
      EXPECT_NEAR(a.mean_ratio, 1.0, 0.01) << what;
      for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
          const double e = expected[size_t(y) * 32 + size_t(x)];
          const double v = film.mean({x, y}).g;
          const double se = std::sqrt(double(film.sample_variance({x, y}).g) / double(film.pixel({x, y}).count));
          EXPECT_NEAR(v, e, 4 * se + 0.01 * e) << what << " pixel " << x << "," << y;
        }
    }
  }
}

}  // namespace
}  // namespace tessera
