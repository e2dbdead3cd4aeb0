// Filter importance sampling: the 1D marginals of the sampled offsets must follow the kernel.
#include "tessera/core/hash.h"
#include "tessera/render/camera.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <sstream>
#include <vector>

namespace tessera {
namespace {

// Pearson chi-square of the offsets' x and y marginals against `cdf` (of the 1D kernel on
// [-r, r]), `bins` equal bins; returns the smaller p-value of the two axes.
double marginal_p_value(const Filter& f, const std::function<double(double)>& cdf, int bins,
                        std::string* msg) {
  const double r = f.radius();
  const int n = 400000;
  std::vector<double> hx(size_t(bins), 0), hy(size_t(bins), 0);
  Pcg32 rng(17);
  for (int i = 0; i < n; ++i) {
    Vec2 o = f.sample({rng.next_float(), rng.next_float()});
    EXPECT_LE(std::abs(o.x), r);
    EXPECT_LE(std::abs(o.y), r);
    int bx = std::clamp(int((o.x + r) / (2 * r) * bins), 0, bins - 1);
    int by = std::clamp(int((o.y + r) / (2 * r) * bins), 0, bins - 1);
    hx[size_t(bx)] += 1;
    hy[size_t(by)] += 1;
  }
  double worst = 1;
  for (auto* h : {&hx, &hy}) {
    double stat = 0;
    for (int b = 0; b < bins; ++b) {
      double lo = -r + 2 * r * b / bins, hi = -r + 2 * r * (b + 1) / bins;
      double e = n * (cdf(hi) - cdf(lo));
      double d = (*h)[size_t(b)] - e;
      stat += d * d / e;
    }
    double p = test::chi2_p_value(stat, bins - 1);
    if (p < worst) {
      worst = p;
      std::ostringstream s;
      s << f.name() << ": statistic " << stat << ", p = " << p;
      *msg = s.str();
    }
  }
  return worst;
}

// Three filters x two axes: Sidak-corrected 0.01.
const double kAlpha = 1.0 - std::pow(0.99, 1.0 / 6.0);

TEST(Filter, BoxMarginalsUniform) {
  auto f = make_box_filter(0.5f);
  EXPECT_EQ(f->name(), "box");
  std::string msg;
  double p = marginal_p_value(*f, [](double x) { return x + 0.5; }, 40, &msg);
  EXPECT_GT(p, kAlpha) << msg;
}

TEST(Filter, TentMarginalsTriangular) {
  const double r = 1.5;
  auto f = make_tent_filter(float(r));
  EXPECT_EQ(f->name(), "tent");
  auto cdf = [r](double x) {
    double t = x / r;
    return t < 0 ? 0.5 * (1 + t) * (1 + t) : 1 - 0.5 * (1 - t) * (1 - t);
  };
  std::string msg;
  double p = marginal_p_value(*f, cdf, 40, &msg);
  EXPECT_GT(p, kAlpha) << msg;
}

TEST(Filter, GaussianMarginalsTruncatedGaussian) {
  const double s = 0.5, r = 2.0;
  auto f = make_gaussian_filter(float(s), float(r));
  EXPECT_EQ(f->name(), "gaussian");
  EXPECT_EQ(f->radius(), 2.f);
  // Mitsuba's kernel: exp(-x^2 / 2 s^2) - exp(-r^2 / 2 s^2) on [-r, r].
  const double bias = std::exp(-r * r / (2 * s * s));
  auto prim = [&](double x) { return s * std::sqrt(M_PI / 2) * std::erf(x / (s * std::sqrt(2.0))) - bias * x; };
  auto cdf = [&](double x) { return (prim(x) - prim(-r)) / (prim(r) - prim(-r)); };
  std::string msg;
  double p = marginal_p_value(*f, cdf, 60, &msg);
  EXPECT_GT(p, kAlpha) << msg;
}

// The wrong kernel must be rejected: a gaussian's samples tested against a tent of equal radius.
TEST(Filter, MarginalTestDetectsWrongKernel) {
  auto f = make_gaussian_filter(0.5f, 2.f);
  auto tent_cdf = [](double x) {
    double t = x / 2.0;
    return t < 0 ? 0.5 * (1 + t) * (1 + t) : 1 - 0.5 * (1 - t) * (1 - t);
  };
  std::string msg;
  EXPECT_LT(marginal_p_value(*f, tent_cdf, 40, &msg), 1e-6);
}

TEST(Filter, SymmetricAroundPixelCentre) {
  auto tent = make_tent_filter(1.f);
  auto gauss = make_gaussian_filter(0.5f, 2.f);
  for (const Filter* f : {tent.get(), gauss.get()}) {
    Vec2 mid = f->sample({0.5f, 0.5f});
    EXPECT_NEAR(mid.x, 0.f, 1e-3f) << f->name();
    Vec2 a = f->sample({0.2f, 0.7f}), b = f->sample({0.8f, 0.3f});
    EXPECT_NEAR(a.x, -b.x, 1e-3f) << f->name();
    EXPECT_NEAR(a.y, -b.y, 1e-3f) << f->name();
  }
}

}  // namespace
}  // namespace tessera
