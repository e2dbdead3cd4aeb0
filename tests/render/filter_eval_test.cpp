// Filter::eval is the normalised density that Filter::sample draws (light tracing splats through
// it): it integrates to 1 over the support, vanishes outside, and a 2D chi-square of sample()
// against eval() accepts each filter.
#include "support/discrete_chi2.h"
#include "tessera/core/hash.h"
#include "tessera/core/rgb.h"  // camera.h uses Rgb without including it
#include "tessera/render/camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace tessera {
namespace {

std::vector<std::unique_ptr<Filter>> all_filters() {
  std::vector<std::unique_ptr<Filter>> f;
  f.push_back(make_box_filter(0.5f));
  f.push_back(make_box_filter(1.3f));
  f.push_back(make_tent_filter(1.f));
  f.push_back(make_tent_filter(1.5f));
  f.push_back(make_gaussian_filter(0.5f, 2.f));
  f.push_back(make_gaussian_filter(0.8f, 1.5f));
  return f;
}

// Integral of eval over [x0, x1] x [y0, y1] by composite Simpson's rule, n (even) intervals per
// axis. Edge nodes are nudged inside so a step on a cell edge (the box) is not double counted.
double cell_integral(const Filter& f, double x0, double x1, double y0, double y1, int n) {
  auto node = [n](int k) { return k == 0 ? 1e-6 : (k == n ? 1.0 - 1e-6 : double(k) / n); };
  auto weight = [n](int k) { return (k == 0 || k == n) ? 1.0 : ((k & 1) ? 4.0 : 2.0); };
  double sum = 0;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      Vec2 p(float(x0 + (x1 - x0) * node(i)), float(y0 + (y1 - y0) * node(j)));
      sum += weight(i) * weight(j) * double(f.eval(p));
    }
  }
  return sum * (x1 - x0) * (y1 - y0) / (9.0 * n * n);
}

// Chi-square of `sampled`'s offsets on a bins x bins grid over its support against the cell
// integrals of `density`'s eval (not renormalised: a kernel off by a factor fails too).
test::DiscreteChi2Result grid_chi2(const Filter& sampled, const Filter& density, int test_count) {
  const int bins = 24, n = 1000000;  // even: the tent's kink at 0 falls on a cell edge
  const double r = sampled.radius(), w = 2 * r / bins;
  std::vector<uint64_t> counts(size_t(bins * bins), 0);
  Pcg32 rng(23);
  for (int k = 0; k < n; ++k) {
    Vec2 o = sampled.sample({rng.next_float(), rng.next_float()});
    int i = std::clamp(int((o.x + r) / w), 0, bins - 1), j = std::clamp(int((o.y + r) / w), 0, bins - 1);
    ++counts[size_t(i * bins + j)];
  }
  std::vector<double> probs(counts.size());
  for (int i = 0; i < bins; ++i) {
    for (int j = 0; j < bins; ++j) {
      const double x0 = -r + i * w, y0 = -r + j * w;
      probs[size_t(i * bins + j)] = cell_integral(density, x0, x0 + w, y0, y0 + w, 8);
    }
  }
  return test::discrete_chi2(counts, probs, 0, 0.0, 0.01, test_count);
}

TEST(FilterEval, IntegratesToOneOverSupport) {
  for (const auto& f : all_filters()) {
    const double r = f->radius();
    double total = 0;
    const int cells = 32;
    for (int i = 0; i < cells; ++i)
      for (int j = 0; j < cells; ++j)
        total += cell_integral(*f, -r + 2 * r * i / cells, -r + 2 * r * (i + 1) / cells, -r + 2 * r * j / cells,
                               -r + 2 * r * (j + 1) / cells, 8);
    EXPECT_NEAR(total, 1.0, 1e-3) << f->name() << " radius " << r;
  }
}

TEST(FilterEval, ZeroOutsideSupportAndPositiveInside) {
  for (const auto& f : all_filters()) {
    const float r = f->radius();
    for (Vec2 o : {Vec2(1.01f * r, 0.f), Vec2(0.f, -1.01f * r), Vec2(1.5f * r, 1.5f * r), Vec2(-3.f * r, 0.2f * r)})
      EXPECT_EQ(f->eval(o), 0.f) << f->name() << " at " << o.x << "," << o.y;
    EXPECT_GT(f->eval({0.f, 0.f}), 0.f) << f->name();
    EXPECT_GT(f->eval({0.5f * r, -0.5f * r}), 0.f) << f->name();
    EXPECT_EQ(f->eval({0.3f * r, 0.1f * r}), f->eval({-0.3f * r, -0.1f * r})) << f->name();
  }
}

// Closed forms at the centre: box 1/(2r)^2, tent 1/r^2, gaussian (1 - b)^2 / norm^2 with Mitsuba's
// shifted kernel exp(-x^2 / 2s^2) - b, b = exp(-r^2 / 2s^2).
TEST(FilterEval, CentreValues) {
  EXPECT_NEAR(make_box_filter(0.5f)->eval({0.f, 0.f}), 1.f, 1e-6f);
  EXPECT_NEAR(make_tent_filter(1.5f)->eval({0.f, 0.f}), 1.f / 2.25f, 1e-6f);
  EXPECT_NEAR(make_tent_filter(1.5f)->eval({0.75f, 0.f}), 0.5f / 2.25f, 1e-6f);
  const double s = 0.5, r = 2.0, b = std::exp(-r * r / (2 * s * s));
  const double norm = s * std::sqrt(2 * M_PI) * std::erf(r / (s * std::sqrt(2.0))) - 2 * r * b;
  EXPECT_NEAR(make_gaussian_filter(0.5f, 2.f)->eval({0.f, 0.f}), (1 - b) * (1 - b) / (norm * norm), 1e-5);
}

TEST(FilterEval, ChiSquareSampleAgainstEval) {
  auto filters = all_filters();
  for (const auto& f : filters) {
    auto r = grid_chi2(*f, *f, int(filters.size()));
    EXPECT_TRUE(r.passed) << f->name() << " radius " << f->radius() << ": " << r.message;
  }
}

// The harness must reject a kernel that sample() does not draw: gaussian samples against a tent.
TEST(FilterEval, ChiSquareDetectsWrongKernel) {
  auto gauss = make_gaussian_filter(0.5f, 2.f);
  auto tent = make_tent_filter(2.f);
  EXPECT_FALSE(grid_chi2(*gauss, *tent, 1).passed);
}

}  // namespace
}  // namespace tessera
