#include "tessera/core/distribution.h"

#include <algorithm>
#include <cmath>

namespace tessera {

double CdfTable::fill(const float* weights, uint32_t n, CdfEntry* e, uint32_t* guide, double& total_norm) {
  double sum = 0;
  e[0].cdf = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const float w = weights[i];
    e[i].func = (std::isfinite(w) && w > 0.f) ? double(w) : 0.0;
    sum += e[i].func;
    e[i + 1].cdf = sum;
  }
  e[n].func = 0;
  total_norm = 1;
  if (sum > 0) {
    for (uint32_t i = 1; i <= n; ++i) e[i].cdf /= sum;
    total_norm = sum;
  } else if (n > 0) {
    // All-zero weights: fall back to uniform so sampling never divides by zero.
    for (uint32_t i = 0; i < n; ++i) {
      e[i].func = 1.0;
      e[i + 1].cdf = double(i + 1) / double(n);
    }
    total_norm = double(n);
  }
  if (n > 0) e[n].cdf = 1.0;
  const uint32_t k = buckets(n);
  for (uint32_t b = 0, i = 0; n > 0 && b <= k; ++b) {
    const double edge = double(b) / double(k);
    while (i < n && e[i + 1].cdf <= edge) ++i;
    guide[b] = i;
  }
  return sum;
}

uint32_t CdfTable::sample_discrete(float u, float* pmf_out, float* u_remapped) const {
  if (n == 0) {
    if (pmf_out) *pmf_out = 0.f;
    return 0;
  }
  // u * K is exact in double (24-bit mantissa times K < 2^29), so bucket b satisfies
  // b / K <= u < (b + 1) / K, and rounding b / K to double is monotonic: the largest i with
  // cdf_i <= u lies in [guide[b], guide[b + 1]].
  const uint32_t k = buckets(n);
  const double x = double(u) * double(k);
  const uint32_t b = x > 0.0 ? uint32_t(std::min(x, double(k - 1))) : 0;
  const CdfEntry* first = entries + guide[b] + 1;
  const CdfEntry* last = entries + guide[b + 1] + 1;
  const CdfEntry* it = std::upper_bound(first, last, double(u), [](double v, const CdfEntry& e) { return v < e.cdf; });
  uint32_t i = std::min(uint32_t(it - entries) - 1, n - 1);
  // Skip empty bins (u on their zero-width interval, or on a bucket edge).
  while (i + 1 < n && entries[i].func == 0.0) ++i;
  while (i > 0 && entries[i].func == 0.0) --i;
  if (pmf_out) *pmf_out = float(entries[i].func / total_norm);
  if (u_remapped) {
    const double width = entries[i + 1].cdf - entries[i].cdf;
    const double r = width > 0 ? (double(u) - entries[i].cdf) / width : 0.0;
    *u_remapped = std::min(float(std::clamp(r, 0.0, 1.0)), 0x1.fffffep-1f);
  }
  return i;
}

float CdfTable::sample_continuous(float u, float* pdf, uint32_t* index) const {
  float remapped = 0.f;
  const uint32_t i = sample_discrete(u, nullptr, &remapped);
  if (index) *index = i;
  if (n == 0) {
    if (pdf) *pdf = 0.f;
    return 0.f;
  }
  if (pdf) *pdf = float(entries[i].func * double(n) / total_norm);
  return std::min((float(i) + remapped) / float(n), 0x1.fffffep-1f);
}

float CdfTable::pdf_continuous(float x) const {
  if (n == 0 || !(x >= 0.f && x < 1.f)) return 0.f;
  const uint32_t i = std::min(uint32_t(x * float(n)), n - 1);
  return float(entries[i].func * double(n) / total_norm);
}

Distribution1D::Distribution1D(const std::vector<float>& weights) {
  const uint32_t n = uint32_t(weights.size());
  entries_.resize(size_t(n) + 1);
  guide_.resize(size_t(CdfTable::buckets(n)) + 1);
  table_ = {entries_.data(), guide_.data(), n, 1};
  total_ = CdfTable::fill(weights.data(), n, entries_.data(), guide_.data(), table_.total_norm);
}

Distribution2D::Distribution2D(const std::vector<float>& weights, int width, int height)
    : width_(width), height_(height) {
  const size_t stride = size_t(width) + 1, guide_stride = size_t(CdfTable::buckets(uint32_t(width))) + 1;
  entries_.resize(stride * size_t(height));
  guide_.resize(guide_stride * size_t(height));
  row_norm_.resize(size_t(height));
  // A row with no weight keeps marginal weight 0 (its uniform fallback is never chosen).
  std::vector<float> row_sums(static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    row_sums[size_t(y)] =
        float(CdfTable::fill(weights.data() + size_t(y) * size_t(width), uint32_t(width), entries_.data() + size_t(y) * stride,
                             guide_.data() + size_t(y) * guide_stride, row_norm_[size_t(y)]));
  }
  marginal_ = Distribution1D(row_sums);
}

CdfTable Distribution2D::row(size_t y) const {
  const size_t guide_stride = size_t(CdfTable::buckets(uint32_t(width_))) + 1;
  return {entries_.data() + y * (size_t(width_) + 1), guide_.data() + y * guide_stride, uint32_t(width_), row_norm_[y]};
}

Vec2 Distribution2D::sample(Vec2 u, float* pdf) const {
  float pdf_v = 0.f, pdf_u = 0.f;
  uint32_t y = 0;
  const float v = marginal_.sample_continuous(u.y, &pdf_v, &y);
  const float x = row(y).sample_continuous(u.x, &pdf_u, nullptr);
  if (pdf) *pdf = pdf_u * pdf_v;
  return {x, v};
}

float Distribution2D::pdf(Vec2 uv) const {
  if (width_ == 0 || height_ == 0) return 0.f;
  if (!(uv.x >= 0.f && uv.x < 1.f && uv.y >= 0.f && uv.y < 1.f)) return 0.f;
  const int y = std::min(int(uv.y * float(height_)), height_ - 1);
  return marginal_.pdf_continuous(uv.y) * row(size_t(y)).pdf_continuous(uv.x);
}

}  // namespace tessera
