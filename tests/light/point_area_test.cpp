// point and area lights: values of sample_li(), and chi-square tests of area-light sampling
// against pdf_li() (the density MIS relies on).
#include "tessera/core/sampling.h"
#include "tessera/light/area.h"
#include "tessera/light/point.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

namespace tessera {
namespace {

// A parallelogram p0 + a e1 + b e2, normal normalize(e1 x e2) (flipped if asked), sampled uniformly.
// Implemented here so that the light is tested independently of the mesh code.
class Parallelogram final : public Shape {
 public:
  Parallelogram(Vec3 p0, Vec3 e1, Vec3 e2, bool flip) : p0_(p0), e1_(e1), e2_(e2) {
    Vec3 c = cross(e1, e2);
    area_ = length(c);
    n_ = c / area_ * (flip ? -1.f : 1.f);
  }
  Kind kind() const override { return Kind::Mesh; }
  uint32_t num_primitives() const override { return 0; }
  Bounds3 bounds() const override { return {}; }
  float area() const override { return area_; }
  void sample_area(Vec2 u, Vec3& p, Vec3& n, float& pdf_area) const override {
    p = p0_ + e1_ * u.x + e2_ * u.y;
    n = n_;
    pdf_area = 1.f / area_;
  }
  void fill_interaction(const Ray&, const Hit&, uint32_t, SurfaceInteraction&) const override {}

  /// The surface point a ray from `o` along `d` hits, if any.
  std::optional<SurfaceInteraction> hit(Vec3 o, Vec3 d) const {
    Vec3 nn = cross(e1_, e2_);
    float denom = dot(nn, d);
    if (std::abs(denom) < 1e-12f) return std::nullopt;
    float t = dot(nn, p0_ - o) / denom;
    if (t <= 0.f) return std::nullopt;
    Vec3 p = o + d * t, q = p - p0_;
    // Solve q = a e1 + b e2 (least squares via the Gram matrix).
    float e11 = dot(e1_, e1_), e12 = dot(e1_, e2_), e22 = dot(e2_, e2_);
    float r1 = dot(q, e1_), r2 = dot(q, e2_), det = e11 * e22 - e12 * e12;
    float a = (r1 * e22 - r2 * e12) / det, b = (r2 * e11 - r1 * e12) / det;
    if (a < 0.f || a > 1.f || b < 0.f || b > 1.f) return std::nullopt;
    SurfaceInteraction si;
    si.p = p;
    si.t = t;
    si.ng = n_;
    si.shape = this;
    return si;
  }

 private:
  Vec3 p0_, e1_, e2_, n_;
  float area_;
};

TEST(PointLight, InverseSquareAndPower) {
  auto light = make_point_light({1.f, 2.f, 3.f}, Rgb(2.f, 4.f, 6.f));
  EXPECT_TRUE(light->is_delta());
  EXPECT_FALSE(light->is_infinite());
  LightSample ls;
  ASSERT_TRUE(light->sample_li({1.f, 2.f, 1.f}, {0.3f, 0.9f}, ls));
  EXPECT_TRUE(ls.delta);
  EXPECT_EQ(ls.pdf, 1.f);
  EXPECT_EQ(ls.wi, Vec3(0.f, 0.f, 1.f));
  EXPECT_FLOAT_EQ(ls.dist, 2.f);
  EXPECT_FLOAT_EQ(ls.li.r, 0.5f);
  EXPECT_FLOAT_EQ(ls.li.b, 1.5f);
  EXPECT_EQ(ls.p_light, Vec3(1.f, 2.f, 3.f));
  EXPECT_NEAR(light->power(), 4.f * kPi * Rgb(2.f, 4.f, 6.f).luminance(), 1e-4f);  // as rgb.h says
  // Not hit by rays: no pdf for MIS.
  SurfaceInteraction si;
  EXPECT_EQ(light->pdf_li({0.f, 0.f, 0.f}, si), 0.f);
}

TEST(AreaLight, OneSidedEmissionAndPower) {
  Parallelogram quad({-1.f, -1.f, 0.f}, {2.f, 0.f, 0.f}, {0.f, 2.f, 0.f}, false);  // normal +z
  auto light = make_area_light(quad, Rgb(3.f));
  EXPECT_FALSE(light->is_delta());
  EXPECT_NEAR(light->power(), kPi * 4.f * 3.f, 1e-4f);
  SurfaceInteraction si = *quad.hit({0.f, 0.f, 1.f}, {0.f, 0.f, -1.f});
  EXPECT_EQ(light->le(si, {0.f, 0.f, 1.f}), Rgb(3.f));
  EXPECT_TRUE(light->le(si, {0.f, 0.f, -1.f}).is_black());
  // From behind, every sample is rejected.
  LightSample ls;
  EXPECT_FALSE(light->sample_li({0.f, 0.f, -1.f}, {0.4f, 0.6f}, ls));
  // From the front: pdf = d^2 / (cos * area).
  ASSERT_TRUE(light->sample_li({0.f, 0.f, 2.f}, {0.5f, 0.5f}, ls));
  EXPECT_NEAR(ls.wi.z, -1.f, 1e-6f);
  EXPECT_NEAR(ls.dist, 2.f, 1e-6f);
  EXPECT_NEAR(ls.pdf, 4.f / 4.f, 1e-5f);
  EXPECT_EQ(ls.li, Rgb(3.f));
  EXPECT_EQ(ls.n_light, Vec3(0.f, 0.f, 1.f));
  SurfaceInteraction at = *quad.hit({0.f, 0.f, 2.f}, ls.wi);
  EXPECT_NEAR(light->pdf_li({0.f, 0.f, 2.f}, at), ls.pdf, 1e-5f);
}

// The solid-angle density of sample_li() equals pdf_li() at the point the direction hits, for
// several shapes and reference points (including grazing and flipped-normal configurations).
TEST(AreaLight, Chi2SamplingMatchesPdfLi) {
  struct Case {
    Parallelogram quad;
    Vec3 ref;
  };
  Case cases[] = {
      {Parallelogram({-1.f, -1.f, 1.f}, {2.f, 0.f, 0.f}, {0.f, 2.f, 0.f}, true), {0.f, 0.f, 0.f}},
      {Parallelogram({0.2f, -0.5f, 0.3f}, {1.f, 0.2f, 0.f}, {0.f, 0.4f, 0.8f}, true), {0.f, 0.1f, 0.f}},
      {Parallelogram({-1.5f, -0.2f, -0.5f}, {3.f, 0.f, 0.f}, {0.f, 0.4f, 0.f}, false), {0.1f, 0.f, -0.3f}},
      // Back faces the reference: every sample invalid, pdf must integrate to ~0 there too.
      {Parallelogram({-1.f, -1.f, 1.f}, {2.f, 0.f, 0.f}, {0.f, 2.f, 0.f}, false), {0.f, 0.f, 0.f}},
  };
  test::Chi2Options o;
  o.test_count = 3;
  o.name = "area light";
  o.integration_resolution = 32;  // the pdf is discontinuous at the shapes' edges
  int n = 0;
  for (const Case& c : cases) {
    auto light = make_area_light(c.quad, Rgb(1.f));
    auto r = test::chi2_test(
        [&](Vec2 u) {
          LightSample ls;
          if (!light->sample_li(c.ref, u, ls)) return test::Chi2Sample{Vec3(), 0.f, false};
          return test::Chi2Sample{ls.wi, ls.pdf, true};
        },
        [&](Vec3 w) {
          auto si = c.quad.hit(c.ref, w);
          return si ? double(light->pdf_li(c.ref, *si)) * (dot(si->ng, w) < 0.f ? 1.0 : 0.0) : 0.0;
        },
        o);
    if (n++ < 3) {
      EXPECT_TRUE(r.passed) << r.message;
    } else {
      EXPECT_EQ(r.valid_samples, 0u);
    }
  }
}

}  // namespace
}  // namespace tessera

namespace tessera {
namespace {

// First intersection of the ray ref + t w with a sphere, as the scene would report it.
std::optional<SurfaceInteraction> hit_sphere(const SphereShape& s, bool flipped, Vec3 ref, Vec3 w) {
  Vec3 oc = ref - s.center();
  double b = dot(oc, w), c = double(dot(oc, oc)) - double(s.radius()) * s.radius();
  double disc = b * b - c;
  if (disc < 0) return std::nullopt;
  double sq = std::sqrt(disc), t = -b - sq;
  if (t <= 0) t = -b + sq;
  if (t <= 0) return std::nullopt;
  SurfaceInteraction si;
  si.p = ref + w * float(t);
  Vec3 n = normalize(si.p - s.center());
  si.ng = flipped ? -n : n;
  si.shape = &s;
  return si;
}

// Sphere lights: cone sampling from outside, area sampling from inside, for outward and inward
// (flipped) emission. (Small cones, a few bins wide, are tested separately below: there the
// harness's integration error at the cone's edge outgrows the sampling noise.)
TEST(AreaLight, Chi2SphereLights) {
  struct Case {
    Vec3 ref;
    bool flipped;
    bool expect_samples;
  };
  const Case cases[] = {
      // Oblique views: a cone edge aligned with the (cos theta, phi) grid defeats the harness's
      // Simpson integration, which is only accurate for discontinuities crossing bins obliquely.
      {{1.7f, -2.1f, -1.9f}, false, true},  // outside, wide cone
      {{2.f, 1.f, 1.3f}, false, true},      // outside, close
      {{0.2f, -0.3f, 0.1f}, true, true},  // inside a sphere that emits inwards
      {{0.f, 0.f, -3.f}, true, false},    // outside a sphere that emits inwards: nothing reaches
      {{0.2f, -0.3f, 0.1f}, false, false},  // inside a sphere that emits outwards: nothing
  };
  test::Chi2Options o;
  o.test_count = 3;
  o.name = "sphere light";
  o.integration_resolution = 32;  // the pdf is discontinuous at the silhouette
  for (const Case& c : cases) {
    SphereShape sphere(Vec3(0.f, 0.f, 0.5f), 1.f, c.flipped);
    auto light = make_area_light(sphere, Rgb(1.f));
    auto r = test::chi2_test(
        [&](Vec2 u) {
          LightSample ls;
          if (!light->sample_li(c.ref, u, ls)) return test::Chi2Sample{Vec3(), 0.f, false};
          // The sampled point is on the sphere, faces the reference and is the first hit.
          EXPECT_NEAR(length(ls.p_light - sphere.center()), 1.f, 1e-4f);
          EXPECT_LT(dot(ls.n_light, ls.wi), 0.f);
          // Away from the silhouette (where float error moves the first hit a long way), the
          // point is where the sampled direction first meets the sphere.
          if (-dot(ls.n_light, ls.wi) > 0.1f) {
            auto si = hit_sphere(sphere, c.flipped, c.ref, ls.wi);
            EXPECT_TRUE(si.has_value());
            if (si) {
              EXPECT_NEAR(length(si->p - ls.p_light), 0.f, 1e-3f);
            }
          }
          return test::Chi2Sample{ls.wi, ls.pdf, true};
        },
        [&](Vec3 w) {
          auto si = hit_sphere(sphere, c.flipped, c.ref, w);
          if (!si || dot(si->ng, w) >= 0.f) return 0.0;
          return double(light->pdf_li(c.ref, *si));
        },
        o);
    if (c.expect_samples) {
      EXPECT_TRUE(r.passed) << "ref (" << c.ref.x << "," << c.ref.y << "," << c.ref.z << ")\n" << r.message;
    } else {
      EXPECT_EQ(r.valid_samples, 0u);
    }
  }
}

// Far away (sin^2 theta_max below the first-order threshold) the cone is sampled through its
// small-angle expansion: directions stay inside the cone, are uniform in solid angle (half of
// them within theta_max / sqrt(2)), and the pdf is 1 / (pi theta_max^2) to first order.
TEST(AreaLight, SmallSphereConeFarAway) {
  SphereShape sphere(Vec3(0.f, 0.f, 0.f), 0.5f, false);
  auto light = make_area_light(sphere, Rgb(1.f));
  const Vec3 ref(0.f, 0.f, -40.f);
  const double sin_max = 0.5 / 40.0, theta_max = std::asin(sin_max);
  Pcg32 rng(5);
  int inside_half = 0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    LightSample ls;
    ASSERT_TRUE(light->sample_li(ref, {rng.next_float(), rng.next_float()}, ls));
    double theta = std::acos(std::clamp(double(ls.wi.z), -1.0, 1.0));
    ASSERT_LE(theta, theta_max * 1.001);
    if (theta < theta_max / std::sqrt(2.0)) ++inside_half;
    EXPECT_NEAR(ls.pdf, 1.0 / (kPi * sin_max * sin_max), 1e-3 / (kPi * sin_max * sin_max));
    EXPECT_NEAR(length(ls.p_light - sphere.center()), 0.5f, 1e-4f);
  }
  EXPECT_NEAR(double(inside_half) / n, 0.5, 5 * 0.5 / std::sqrt(double(n)));
}

}  // namespace
}  // namespace tessera
