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

Distribution1D::Distribution1D(const std::vector<float>& weights) {
  size_t n = weights.size();
  func_.resize(n);
  cdf_.resize(n + 1);
  cdf_[0] = 0;
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    float w = weights[i];
    func_[i] = (std::isfinite(w) && w > 0.f) ? double(w) : 0.0;
    sum += func_[i];
    cdf_[i + 1] = sum;
  }
  total_ = sum;
  if (sum > 0) {
    for (size_t i = 1; i <= n; ++i) cdf_[i] /= sum;
    total_norm_ = sum;
  } else if (n > 0) {
    // All-zero weights: fall back to uniform so sampling never divides by zero.
    for (size_t i = 0; i < n; ++i) {
      func_[i] = 1.0;
      cdf_[i + 1] = double(i + 1) / double(n);
    }
    total_norm_ = double(n);
  }
  if (n > 0) cdf_[n] = 1.0;
}

uint32_t Distribution1D::sample_discrete(float u, float* pmf_out, float* u_remapped) const {
  size_t n = size();
  if (n == 0) {
    if (pmf_out) *pmf_out = 0.f;
    return 0;
  }
  // Largest i with cdf_[i] <= u, skipping empty bins.
  auto it = std::upper_bound(cdf_.begin(), cdf_.end(), double(u));
  size_t i = size_t(std::clamp<std::ptrdiff_t>(it - cdf_.begin() - 1, 0, std::ptrdiff_t(n) - 1));
  while (i + 1 < n && func_[i] == 0.0) ++i;
  while (i > 0 && func_[i] == 0.0) --i;
  double width = cdf_[i + 1] - cdf_[i];
  if (pmf_out) *pmf_out = float(func_[i] / total_norm_);
  if (u_remapped) {
    double r = width > 0 ? (double(u) - cdf_[i]) / width : 0.0;
    *u_remapped = std::min(float(std::clamp(r, 0.0, 1.0)), 0x1.fffffep-1f);
  }
  return uint32_t(i);
}

float Distribution1D::sample_continuous(float u, float* pdf, uint32_t* index) const {
  float remapped = 0.f;
  uint32_t i = sample_discrete(u, nullptr, &remapped);
  if (index) *index = i;
  size_t n = size();
  if (n == 0) {
    if (pdf) *pdf = 0.f;
    return 0.f;
  }
  if (pdf) *pdf = float(func_[i] * double(n) / total_norm_);
  float x = (float(i) + remapped) / float(n);
  return std::min(x, 0x1.fffffep-1f);
}

float Distribution1D::pdf_continuous(float x) const {
  size_t n = size();
  if (n == 0 || !(x >= 0.f && x < 1.f)) return 0.f;
  size_t i = std::min(size_t(x * float(n)), n - 1);
  return float(func_[i] * double(n) / total_norm_);
}

Distribution2D::Distribution2D(const std::vector<float>& weights, int width, int height)
    : width_(width), height_(height) {
  conditional_.reserve(size_t(height));
  std::vector<float> row_sums(static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    std::vector<float> row(weights.begin() + size_t(y) * width, weights.begin() + size_t(y + 1) * width);
    conditional_.emplace_back(row);
    // A row with no weight keeps marginal weight 0 (its uniform fallback is never chosen).
    double s = 0;
    for (float w : row) s += (std::isfinite(w) && w > 0.f) ? w : 0.f;
    row_sums[size_t(y)] = float(s);
  }
  marginal_ = Distribution1D(row_sums);
}

Vec2 Distribution2D::sample(Vec2 u, float* pdf) const {
  float pdf_v = 0.f, pdf_u = 0.f;
  uint32_t row = 0;
  float v = marginal_.sample_continuous(u.y, &pdf_v, &row);
  float x = conditional_[row].sample_continuous(u.x, &pdf_u);
  if (pdf) *pdf = pdf_u * pdf_v;
  return {x, v};
}

float Distribution2D::pdf(Vec2 uv) const {
  if (width_ == 0 || height_ == 0) return 0.f;
  if (!(uv.x >= 0.f && uv.x < 1.f && uv.y >= 0.f && uv.y < 1.f)) return 0.f;
  int row = std::min(int(uv.y * float(height_)), height_ - 1);
  return marginal_.pdf_continuous(uv.y) * conditional_[size_t(row)].pdf_continuous(uv.x);
}

}  // namespace tessera
