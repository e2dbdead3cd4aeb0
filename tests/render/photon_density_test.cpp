// sppm's photon density estimate against closed forms: the radiance of a diffuse plane under a
// point light and under a square area light, gathered from photons alone (photon_direct) with a
// fixed radius (alpha 1). Per block of pixels the estimate must match
//   (a) the closed-form irradiance averaged over the gather disk, within the photon noise: the
//       estimator itself, at any radius;
//   (b) the closed-form irradiance at the point, within a tolerance that shrinks as r^2 (the
//       disk average's second-order deviation) plus the noise: the estimate converges to the
//       irradiance as the radius shrinks.
#include "tessera/render/sppm.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "tessera/sequence/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

namespace tessera {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kAlbedo = 0.5, kHeight = 1.0;
constexpr int kRes = 32, kBlock = 8;

// A plane z = 0 seen from above by an orthographic camera over [-1, 1]^2, lit by `light` (at
// height 1, outside the camera's view).
std::unique_ptr<Scene> plane_scene(const std::string& light, float radius, uint64_t photons) {
  const std::string xml = R"(<scene version="3.0.0">
  <integrator type="sppm"><integer name="photon_count" value=")" + std::to_string(photons) + R"("/>
    <float name="initial_radius" value=")" + std::to_string(radius) + R"("/><float name="alpha" value="1"/></integrator>
  <sensor type="orthographic"><transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="independent"/>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="32"/><rfilter type="box"/></film>
  </sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/></transform>
    <bsdf type="diffuse"><rgb name="reflectance" value="0.5"/></bsdf></shape>
  )" + light + "\n</scene>";
  LoadResult r = load_scene(parse_scene_string(xml, "photon_density_test.xml"), LoadOptions{});
  r.scene->integrator.photon_direct = true;
  r.scene->integrator.max_depth = 2;  // (the plane's own light only: nothing else to bounce off)
  return std::move(r.scene);
}

// Lambert's formula: irradiance at `x` (normal +z) from a polygon of radiance `le` facing it.
double polygon_irradiance(const std::vector<Vec3>& poly, Vec3 x, double le) {
  double sum = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const Vec3 a = normalize(poly[i] - x), b = normalize(poly[(i + 1) % poly.size()] - x);
    const double theta = std::acos(std::clamp(double(dot(a, b)), -1.0, 1.0));
    sum += theta * double(normalize(cross(a, b)).z);
  }
  return le * 0.5 * std::abs(sum);
}

// The mean of f over the disk of radius r around (x, y) (polar midpoint rule).
double disk_mean(const std::function<double(Vec3)>& f, Vec3 c, double r) {
  constexpr int kRings = 24, kSpokes = 48;
  double sum = 0, weight = 0;
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j < kSpokes; ++j) {
      const double rho = r * (i + 0.5) / kRings, phi = 2 * kPi * (j + 0.5) / kSpokes;
      sum += rho * f(c + Vec3(float(rho * std::cos(phi)), float(rho * std::sin(phi)), 0.f));
      weight += rho;
    }
  return sum / weight;
}

// Photons are Poisson. A block's mean weighs a photon at x by k(x), the number of the block's
// pixels whose disk holds it, so its relative variance is integral(k^2) / (density photons
// integral(k)^2): that of a count over this area.
double block_effective_area(float r) {
  const double pixel = 2.0 / kRes, side = kBlock * pixel + 2 * r;
  constexpr int kGrid = 200;
  double k1 = 0, k2 = 0;
  for (int j = 0; j < kGrid; ++j)
    for (int i = 0; i < kGrid; ++i) {
      const double x = -r + side * (i + 0.5) / kGrid, y = -r + side * (j + 0.5) / kGrid;
      int k = 0;
      for (int py = 0; py < kBlock; ++py)
        for (int px = 0; px < kBlock; ++px) {
          const double dx = x - (px + 0.5) * pixel, dy = y - (py + 0.5) * pixel;
          k += dx * dx + dy * dy <= double(r) * r;
        }
      k1 += k;
      k2 += double(k) * k;
    }
  const double cell = (side / kGrid) * (side / kGrid);
  return (k1 * cell) * (k1 * cell) / (k2 * cell);
}

struct Deviation {
  double from_disk_mean = 0, from_point = 0, noise = 0;  // worst block, relative; the noise bound used
};

// Renders with radius r and compares 8x8-pixel blocks with the closed form `irradiance`.
// `density(c)`: the fraction of the light's photons expected per unit area at c.
Deviation compare(const Scene& scene, float r, int passes, const std::function<double(Vec3)>& irradiance,
                  const std::function<double(Vec3)>& density) {
  RenderSettings rs;
  rs.spp = passes;
  rs.seed = 7;
  const Film film = render(scene, rs);
  EXPECT_EQ(film.counters().nonfinite, 0u);
  const double photons = double(scene.integrator.photon_count) * passes;
  const double area = block_effective_area(r);
  Deviation d;
  for (int by = 0; by < kRes; by += kBlock)
    for (int bx = 0; bx < kRes; bx += kBlock) {
      double est = 0, at_point = 0, over_disk = 0, mean_density = 0;
      for (int y = by; y < by + kBlock; ++y)
        for (int x = bx; x < bx + kBlock; ++x) {
          const Ray ray = scene.camera->generate_ray_at({x + 0.5f, y + 0.5f}, {0.5f, 0.5f}, 0.f);
          const Vec3 p = ray.o + ray.d * (-ray.o.z / ray.d.z);
          est += film.mean({x, y}).g;
          at_point += kAlbedo / kPi * irradiance(p);
          over_disk += kAlbedo / kPi * disk_mean(irradiance, p, r);
          mean_density += density(p) / (kBlock * kBlock);
        }
      const double noise = 4.0 / std::sqrt(photons * mean_density * area);
      d.noise = std::max(d.noise, noise);
      d.from_disk_mean = std::max(d.from_disk_mean, std::abs(est / over_disk - 1) / noise);
      d.from_point = std::max(d.from_point, std::abs(est / at_point - 1) - noise);
    }
  return d;
}

// The disk average's deviation from the point value is at most about |laplacian E| r^2 / (8 E);
// for lights at height h over the plane that is below 3/4 (r / h)^2 (the point light's centre).
double radius_tolerance(float r) { return 0.75 * (r / kHeight) * (r / kHeight) * 1.5; }

TEST(PhotonDensity, PointLightOnADiffusePlane) {
  const Vec3 light(-1.6f, 0.f, float(kHeight));
  const double intensity = 4.0;
  const auto irradiance = [&](Vec3 p) {
    const Vec3 d = light - p;
    const double dist = length(d);
    return intensity * d.z / (dist * dist * dist);
  };
  for (float r : {0.3f, 0.08f}) {
    const std::string xml_light = "<emitter type=\"point\"><point name=\"position\" x=\"-1.6\" y=\"0\" z=\"1\"/>"
                                  "<rgb name=\"intensity\" value=\"4\"/></emitter>";
    auto scene = plane_scene(xml_light, r, 400000);
    // (Photons leave uniformly over the sphere: their density on the plane is E / (4 pi I).)
    const Deviation d =
        compare(*scene, r, 8, irradiance, [&](Vec3 p) { return irradiance(p) / (4 * kPi * intensity); });
    SCOPED_TRACE("radius " + std::to_string(r));
    EXPECT_LT(d.from_disk_mean, 1.0) << "the estimate is not the disk-averaged irradiance (in noise units)";
    EXPECT_LT(d.from_point, radius_tolerance(r)) << "beyond the radius's tolerance of the irradiance";
  }
}

TEST(PhotonDensity, AreaLightOnADiffusePlane) {
  // A 0.5 x 0.5 square at height 1, centred at x = -1.6, facing down, radiance 8.
  const double le = 8.0, half = 0.25;
  const std::vector<Vec3> square = {{-1.6f - 0.25f, -0.25f, 1.f}, {-1.6f + 0.25f, -0.25f, 1.f},
                                    {-1.6f + 0.25f, 0.25f, 1.f}, {-1.6f - 0.25f, 0.25f, 1.f}};
  const auto irradiance = [&](Vec3 p) { return polygon_irradiance(square, p, le); };
  const double power = le * kPi * (2 * half) * (2 * half);  // emitted flux (cosine-weighted)
  for (float r : {0.3f, 0.08f}) {
    const std::string xml_light =
        "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"0.25\"/><rotate x=\"1\" angle=\"180\"/>"
        "<translate x=\"-1.6\" z=\"1\"/></transform><emitter type=\"area\"><rgb name=\"radiance\" value=\"8\"/></emitter></shape>";
    auto scene = plane_scene(xml_light, r, 400000);
    const Deviation d = compare(*scene, r, 8, irradiance, [&](Vec3 p) { return irradiance(p) / power; });
    SCOPED_TRACE("radius " + std::to_string(r));
    EXPECT_LT(d.from_disk_mean, 1.0) << "the estimate is not the disk-averaged irradiance (in noise units)";
    EXPECT_LT(d.from_point, radius_tolerance(r)) << "beyond the radius's tolerance of the irradiance";
  }
}

}  // namespace
}  // namespace tessera
