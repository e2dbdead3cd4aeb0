// Warping functions from [0,1)^n to common distributions (tabulated ones: core/distribution.h).
// Every pdf here is stated with its measure.
#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

namespace tessera {

/// Cosine-weighted hemisphere around +z (Malley's method, concentric map). pdf = cos/pi (solid angle).
Vec3 square_to_cosine_hemisphere(Vec2 u);
inline float cosine_hemisphere_pdf(float cos_theta) { return cos_theta > 0.f ? cos_theta * kInvPi : 0.f; }
/// Uniform over the unit sphere. pdf = 1/(4 pi) (solid angle).
Vec3 square_to_uniform_sphere(Vec2 u);
/// Uniform over the cone of directions around +z with cos(theta) >= cos_max. pdf = 1/(2 pi (1-cos_max)).
Vec3 square_to_uniform_cone(Vec2 u, float cos_max);
/// Shirley-Chiu concentric square-to-disk map (unit disk).
Vec2 square_to_uniform_disk_concentric(Vec2 u);
/// Uniform barycentrics (b1, b2) over a triangle.
Vec2 square_to_uniform_triangle(Vec2 u);

/// Veach's power heuristic with beta = 2, for two strategies with one sample each.
inline float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (a == 0.f) return 0.f;
  if (!(b < kInfinity)) return 0.f;
  return a / (a + b);
}

}  // namespace tessera
