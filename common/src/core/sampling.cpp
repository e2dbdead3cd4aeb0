#include "tessera/core/sampling.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace tessera {

Vec2 square_to_uniform_disk_concentric(Vec2 u) {
  float ox = 2.f * u.x - 1.f, oy = 2.f * u.y - 1.f;
  if (ox == 0.f && oy == 0.f) return {0.f, 0.f};
  float r, theta;
  if (std::abs(ox) > std::abs(oy)) {
    r = ox;
    theta = (kPi / 4.f) * (oy / ox);
  } else {
    r = oy;
    theta = (kPi / 2.f) - (kPi / 4.f) * (ox / oy);
  }
  return {r * std::cos(theta), r * std::sin(theta)};
}

Vec3 square_to_cosine_hemisphere(Vec2 u) {
  Vec2 d = square_to_uniform_disk_concentric(u);
  float z = std::sqrt(std::max(0.f, 1.f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}

Vec3 square_to_uniform_sphere(Vec2 u) {
  float z = 1.f - 2.f * u.x;
  float r = std::sqrt(std::max(0.f, 1.f - z * z));
  float phi = 2.f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Vec3 square_to_uniform_cone(Vec2 u, float cos_max) {
  float cos_theta = (1.f - u.x) + u.x * cos_max;
  float sin_theta = std::sqrt(std::max(0.f, 1.f - cos_theta * cos_theta));
  float phi = 2.f * kPi * u.y;
  return {std::cos(phi) * sin_theta, std::sin(phi) * sin_theta, cos_theta};
}

Vec2 square_to_uniform_triangle(Vec2 u) {
  // Heitz 2019 "A Low-Distortion Map Between Triangle and Square": keeps stratification.
  float b0, b1;
  if (u.y > u.x) {
    b0 = u.x / 2.f;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2.f;
    b0 = u.x - b1;
  }
  // Returned as (b1, b2): the weights of vertices 1 and 2.
  return {b1, 1.f - b0 - b1};
}

}  // namespace tessera
