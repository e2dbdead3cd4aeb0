// Pixel filters, applied by filter importance sampling: each filter draws film offsets distributed
// like its (separable) kernel, so a pixel is the plain mean of its samples' radiance.
// camera.h uses Rgb without including rgb.h (reported to the lead); included first until fixed.
#include "tessera/core/rgb.h"
#include "tessera/render/camera.h"

#include "tessera/core/check.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera {
namespace {

class BoxFilter final : public Filter {
 public:
  explicit BoxFilter(float radius) : radius_(radius) {}
  Vec2 sample(Vec2 u) const override {
    return {(2.f * u.x - 1.f) * radius_, (2.f * u.y - 1.f) * radius_};
  }
  float radius() const override { return radius_; }
  std::string name() const override { return "box"; }
  float eval(Vec2 o) const override {
    if (std::abs(o.x) > radius_ || std::abs(o.y) > radius_) return 0.f;
    return 1.f / (4.f * radius_ * radius_);
  }

 private:
  float radius_;
};

class TentFilter final : public Filter {
 public:
  explicit TentFilter(float radius) : radius_(radius) {}
  Vec2 sample(Vec2 u) const override { return {sample_1d(u.x), sample_1d(u.y)}; }
  float radius() const override { return radius_; }
  std::string name() const override { return "tent"; }
  float eval(Vec2 o) const override { return eval_1d(o.x) * eval_1d(o.y); }

 private:
  // The normalised triangle (1 - |x|/r) / r, the density sample_1d draws.
  float eval_1d(float x) const { return std::max(0.f, 1.f - std::abs(x) / radius_) / radius_; }
  // Inverse of the tent CDF on [-r, r]: each half holds half of the mass.
  float sample_1d(float u) const {
    if (u < 0.5f) return radius_ * (std::sqrt(2.f * u) - 1.f);
    return radius_ * (1.f - std::sqrt(2.f - 2.f * u));
  }
  float radius_;
};

// Mitsuba's gaussian: exp(-x^2 / (2 stddev^2)) minus its value at the radius (so it reaches zero
// there), per axis. Sampled through a fine tabulated CDF whose bin masses are exact integrals
// (erf), inverted by binary search; within a bin the density is taken as constant, which at 4096
// bins over the support is far below any visible or testable difference.
class GaussianFilter final : public Filter {
 public:
  GaussianFilter(float stddev, float radius) : stddev_(stddev), radius_(radius) {
    TESSERA_CHECK(stddev > 0.f && radius > 0.f);
    const double s = stddev, r = radius;
    const double bias = std::exp(-r * r / (2 * s * s));
    auto integral = [&](double x) {  // antiderivative of exp(-x^2/2s^2) - bias
      return s * std::sqrt(kPi / 2.0) * std::erf(x / (s * std::sqrt(2.0))) - bias * x;
    };
    cdf_.resize(kBins + 1);
    double base = integral(-r);
    for (int i = 0; i <= kBins; ++i) cdf_[size_t(i)] = integral(-r + 2 * r * i / kBins) - base;
    double total = cdf_.back();
    for (double& c : cdf_) c /= total;
    cdf_.back() = 1.0;
    bias_ = bias;
    inv_norm_ = 1.0 / total;
  }
  Vec2 sample(Vec2 u) const override { return {sample_1d(u.x), sample_1d(u.y)}; }
  float radius() const override { return radius_; }
  std::string name() const override { return "gaussian"; }
  // The exact kernel, not the tabulated one sample() inverts: the two differ far below sampling noise.
  float eval(Vec2 o) const override { return float(eval_1d(o.x) * eval_1d(o.y)); }

 private:
  static constexpr int kBins = 4096;

  double eval_1d(float x) const {
    if (std::abs(x) > radius_) return 0.0;
    const double s = stddev_, v = std::exp(-double(x) * x / (2 * s * s)) - bias_;
    return std::max(0.0, v) * inv_norm_;
  }

  float sample_1d(float u) const {
    double x = u;
    auto it = std::upper_bound(cdf_.begin(), cdf_.end(), x);
    size_t i = size_t(std::clamp<std::ptrdiff_t>(it - cdf_.begin() - 1, 0, kBins - 1));
    double width = cdf_[i + 1] - cdf_[i];
    double t = width > 0 ? (x - cdf_[i]) / width : 0.5;
    double pos = -double(radius_) + 2.0 * radius_ * (double(i) + t) / kBins;
    return float(std::clamp(pos, -double(radius_), double(radius_)));
  }

  float stddev_, radius_;
  double bias_ = 0, inv_norm_ = 0;  // kernel offset and 1 / its integral over [-r, r]
  std::vector<double> cdf_;
};

}  // namespace

std::unique_ptr<Filter> make_box_filter(float radius) { return std::make_unique<BoxFilter>(radius); }
std::unique_ptr<Filter> make_tent_filter(float radius) { return std::make_unique<TentFilter>(radius); }
std::unique_ptr<Filter> make_gaussian_filter(float stddev, float radius) {
  return std::make_unique<GaussianFilter>(stddev, radius);
}

}  // namespace tessera
