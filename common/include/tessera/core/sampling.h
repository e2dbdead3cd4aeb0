// Warping functions from [0,1)^n to common distributions, and tabulated distributions. Every pdf
// here is stated with its measure.
#pragma once

#include "tessera/core/ray.h"
#include "tessera/core/vec.h"

#include <cstdint>
#include <vector>

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

/// Piecewise-constant 1D distribution over [0,1) (or over indices for discrete use).
class Distribution1D {
 public:
  Distribution1D() = default;
  /// Negative or non-finite weights count as 0. All-zero weights give a uniform distribution.
  explicit Distribution1D(const std::vector<float>& weights);
  size_t size() const { return func_.size(); }
  /// Sum of the weights (the integral times size()).
  double total() const { return total_; }
  /// Discrete sample: index with probability w[i]/total; `pmf` receives it; `u_remapped` is u
  /// rescaled to [0,1) within the chosen bin, so it can be reused.
  uint32_t sample_discrete(float u, float* pmf = nullptr, float* u_remapped = nullptr) const;
  float pmf(uint32_t i) const { return size() ? float(func_[i] / total_norm_) : 0.f; }
  /// Continuous sample in [0,1); pdf with respect to the unit interval.
  float sample_continuous(float u, float* pdf, uint32_t* index = nullptr) const;
  float pdf_continuous(float x) const;

 private:
  std::vector<double> func_;
  std::vector<double> cdf_;  // size()+1 entries, cdf_[0] = 0, cdf_.back() = 1
  double total_ = 0, total_norm_ = 1;
};

/// Piecewise-constant 2D distribution over [0,1)^2: marginal over rows (v), conditional per row (u).
class Distribution2D {
 public:
  Distribution2D() = default;
  /// `weights` is row-major, `width` columns (u) by `height` rows (v).
  Distribution2D(const std::vector<float>& weights, int width, int height);
  /// Returns (u, v) in [0,1)^2; pdf with respect to the unit square.
  Vec2 sample(Vec2 u, float* pdf) const;
  float pdf(Vec2 uv) const;

 private:
  std::vector<Distribution1D> conditional_;
  Distribution1D marginal_;
  int width_ = 0, height_ = 0;
};

}  // namespace tessera
