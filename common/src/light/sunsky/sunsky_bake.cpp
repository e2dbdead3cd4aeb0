#include "tessera/light/sunsky/sunsky_bake.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace tessera {

namespace {

constexpr double kPiD = 3.14159265358979323846;

// Mitsuba's sample02(i): (van der Corput base 2, second Sobol' dimension), unscrambled.
double radical_inverse_2(uint32_t i) {
  i = (i << 16) | (i >> 16);
  i = ((i & 0x00ff00ffu) << 8) | ((i & 0xff00ff00u) >> 8);
  i = ((i & 0x0f0f0f0fu) << 4) | ((i & 0xf0f0f0f0u) >> 4);
  i = ((i & 0x33333333u) << 2) | ((i & 0xccccccccu) >> 2);
  i = ((i & 0x55555555u) << 1) | ((i & 0xaaaaaaaau) >> 1);
  return double(i) * 0x1p-32;
}

double sobol_2(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1)
    if (i & 1u) r ^= v;
  return double(r) * 0x1p-32;
}

}  // namespace

int sunsky_map_height(int resolution) { return resolution / 2 + 1; }

Image bake_sky_map(const HosekSky& sky, double sun_phi, double stretch, float sky_scale, int width, int height) {
  TESSERA_CHECK(width >= 2 && height >= 3 && stretch >= 1.0);
  Image img(width, height, 3);
  const double sun_theta = sky.sun_theta();
  for (int y = 0; y < height; ++y) {
    const double theta = kPiD * y / (height - 1);
    const double t = theta / stretch;
    // A row on the horizon takes the limit from above (see the header).
    const bool on_horizon = std::abs(t - 0.5 * kPiD) < 1e-9;
    for (int x = 0; x < width; ++x) {
      const double phi = 2.0 * kPiD * (x + 0.5) / width;
      const double cos_gamma =
          std::cos(t) * std::cos(sun_theta) + std::sin(t) * std::sin(sun_theta) * std::cos(phi - sun_phi);
      const double gamma = std::acos(std::clamp(cos_gamma, -1.0, 1.0));
      Rgb v = on_horizon ? sky.eval_above(0.5 * kPiD, gamma) : sky.eval(t, gamma);
      img.set_rgb(x, y, v * sky_scale);
    }
  }
  return img;
}

double sunsky_texel_solid_angle(int y, int width, int height) {
  const double d = kPiD / (height - 1);
  const double th = d * y;
  double integral = 0.0;
  // Falling half on [theta_y, theta_y+1] and rising half on [theta_y-1, theta_y] of the tent.
  if (y + 1 < height) integral += std::cos(th) - (std::sin(th + d) - std::sin(th)) / d;
  if (y > 0) integral += -std::cos(th) + (std::sin(th) - std::sin(th - d)) / d;
  return integral * 2.0 * kPiD / width;
}

size_t sun_splat_sample_count(int resolution, double cone_half_angle) {
  const double half_res2 = double((int64_t(resolution) * int64_t(resolution)) / 2);
  const double n = std::max(100.0, half_res2 * 0.5 * (1.0 - std::cos(cone_half_angle)) * 1000.0);
  // Mitsuba has no cap; 2^24 samples already resolve any cone into a 1e-4-smooth disk.
  return size_t(std::min(n, double(1u << 24)));
}

void splat_sun(Image& map, Vec3 sun_dir, double cone_half_angle, Rgb irradiance, int resolution) {
  const int w = map.width(), h = map.height();
  TESSERA_CHECK(w >= 2 && h >= 3 && cone_half_angle > 0.0);
  const size_t n = sun_splat_sample_count(resolution, cone_half_angle);
  // Orthonormal frame about the sun direction, in double.
  double nz[3] = {sun_dir.x, sun_dir.y, sun_dir.z};
  const double len = std::sqrt(nz[0] * nz[0] + nz[1] * nz[1] + nz[2] * nz[2]);
  for (double& c : nz) c /= len;
  const double sign = std::copysign(1.0, nz[2]);
  const double a = -1.0 / (sign + nz[2]), b = nz[0] * nz[1] * a;
  const double tx[3] = {1.0 + sign * nz[0] * nz[0] * a, sign * b, -sign * nz[0]};
  const double ty[3] = {b, sign + nz[1] * nz[1] * a, -nz[1]};

  std::vector<double> inv_row_solid_angle(static_cast<size_t>(h));
  for (int y = 0; y < h; ++y) inv_row_solid_angle[size_t(y)] = 1.0 / sunsky_texel_solid_angle(y, w, h);
  std::vector<double> acc(size_t(w) * size_t(h) * 3, 0.0);
  const double one_minus_cos = 1.0 - std::cos(cone_half_angle);
  const double e[3] = {irradiance.r / double(n), irradiance.g / double(n), irradiance.b / double(n)};
  for (size_t i = 0; i < n; ++i) {
    const double cos_t = 1.0 - radical_inverse_2(uint32_t(i)) * one_minus_cos;
    const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
    const double az = 2.0 * kPiD * sobol_2(uint32_t(i));
    const double ca = std::cos(az) * sin_t, sa = std::sin(az) * sin_t;
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = cos_t * nz[k] + ca * tx[k] + sa * ty[k];
    // Light-space (u, v) as in envmap_direction_to_uv, then the lookup's texel coordinates.
    double u = std::atan2(d[0], -d[2]) / (2.0 * kPiD);
    if (u < 0.0) u += 1.0;
    const double v = std::atan2(std::sqrt(d[0] * d[0] + d[2] * d[2]), d[1]) / kPiD;
    double fx = u * w - 0.5;
    fx -= std::floor(fx / w) * w;
    const int x0 = std::min(int(fx), w - 1), x1 = x0 + 1 == w ? 0 : x0 + 1;
    const double ax = std::clamp(fx - x0, 0.0, 1.0);
    const double fy = std::clamp(v, 0.0, 1.0) * (h - 1);
    const int y0 = std::min(int(fy), h - 2);
    const double ay = std::clamp(fy - y0, 0.0, 1.0);
    const int xs[2] = {x0, x1}, ys[2] = {y0, y0 + 1};
    const double wx[2] = {1.0 - ax, ax}, wy[2] = {1.0 - ay, ay};
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) {
        const double wgt = wx[k] * wy[j] * inv_row_solid_angle[size_t(ys[j])];
        double* t = &acc[(size_t(ys[j]) * size_t(w) + size_t(xs[k])) * 3];
        for (int c = 0; c < 3; ++c) t[c] += wgt * e[c];
      }
  }
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double* t = &acc[(size_t(y) * size_t(w) + size_t(x)) * 3];
      if (t[0] == 0.0 && t[1] == 0.0 && t[2] == 0.0) continue;
      map.set_rgb(x, y, map.rgb(x, y) + Rgb(float(t[0]), float(t[1]), float(t[2])));
    }
}

}  // namespace tessera
