// bumpmap (Mitsuba 0.6): a flat map is exactly the nested BSDF; a ramp tilts the normal by the
// analytic angle, through uv scaling and `scale`; sample() matches pdf() (chi-square) over the
// tilted frame; weight == eval / pdf; white-diffuse albedo matches the clipped cosine lobe;
// degenerate parameterisations and bad texels never give NaN; dp/du, dp/dv of the shapes.
#include "bsdf/perturbed_test_util.h"
#include "tessera/render/shape.h"

#include "bsdf/bsdf_test_util.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>

namespace tessera {
namespace {

using test::direction_deg;
using test::expect_finite_everywhere;

Vec3 tilted_normal(Vec2 grad, Vec3 dpdu, Vec3 dpdv) {
  // For orthogonal dp/du, dp/dv in the z = 0 plane: n ~ (-grad_u/|dpdu|, -grad_v/|dpdv|, 1) in
  // the (dpdu, dpdv) axes.
  Vec3 eu = normalize(dpdu), ev = normalize(dpdv);
  return normalize(eu * (-grad.x / length(dpdu)) + ev * (-grad.y / length(dpdv)) + Vec3(0.f, 0.f, 1.f));
}

TEST(BumpMap, FlatMapIsExactlyTheNestedBsdf) {
  SurfaceInteraction si = test::flat_si();
  si.shading = Frame(normalize(Vec3(0.3f, -0.2f, 1.f)));  // not the identity: no accidental exactness
  si.dpdu = Vec3(0.7f, 0.4f, 0.1f);
  auto diffuse = test::white_diffuse(0.6f);
  auto gold = test::rough_gold();
  std::shared_ptr<const Texture> flats[] = {std::make_shared<ConstantTexture>(Rgb(0.7f)),
                                            test::ramp_texture(0.f, 0.f)};
  for (const auto& flat : flats) {
    for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
      auto bump = make_bumpmap_bsdf(nested, flat);
      ASSERT_NO_FATAL_FAILURE(test::expect_flat_map_is_nested(*bump, *nested, si, 3));
    }
  }
}

TEST(BumpMap, BitmapGradientOfARamp) {
  SurfaceInteraction si = test::flat_si({0.3f, 0.55f});
  Vec2 g = test::ramp_texture(0.8f, -0.3f)->eval_1_gradient(si);
  EXPECT_NEAR(g.x, 0.8f, 1e-4f);
  EXPECT_NEAR(g.y, -0.3f, 1e-4f);
  // to_uv: uv' = (2u, 3v) + offset -> the chain rule scales by 2 and 3.
  UvMapping scaled(Transform::translate(Vec3(0.1f, -0.2f, 0.f)) * Transform::scale(Vec3(2.f, 3.f, 1.f)));
  si.uv = Vec2(0.2f, 0.25f);
  g = test::ramp_texture(0.8f, -0.3f, 64, 64, scaled)->eval_1_gradient(si);
  EXPECT_NEAR(g.x, 1.6f, 1e-3f);
  EXPECT_NEAR(g.y, -0.9f, 1e-3f);
  // Beyond a clamped edge the interpolant is flat.
  si.uv = Vec2(0.999f, 0.5f);
  EXPECT_NEAR(test::ramp_texture(0.8f, 0.f)->eval_1_gradient(si).x, 0.f, 1e-6f);
  // The value and its derivative agree (central difference of eval_1).
  auto ramp = test::ramp_texture(0.8f, -0.3f, 8, 8);
  SurfaceInteraction a = test::flat_si({0.37f, 0.41f}), b = a;
  a.uv.x -= 1e-3f;
  b.uv.x += 1e-3f;
  EXPECT_NEAR((ramp->eval_1(b) - ramp->eval_1(a)) / 2e-3f, ramp->eval_1_gradient(test::flat_si({0.37f, 0.41f})).x,
              2e-2f);
}

TEST(BumpMap, RampTiltsTheNormalByTheAnalyticAngle) {
  auto diffuse = test::white_diffuse();
  struct Case {
    Vec2 slope;
    Vec3 dpdu, dpdv;
  };
  const Case cases[] = {{{0.5f, 0.f}, {1, 0, 0}, {0, 1, 0}},
                        {{0.5f, -0.25f}, {2, 0, 0}, {0, 0.5f, 0}},
                        {{1.f, 0.f}, {0, 1, 0}, {-1, 0, 0}}};
  for (const Case& c : cases) {
    SurfaceInteraction si = test::flat_si();
    si.dpdu = c.dpdu;
    si.dpdv = c.dpdv;
    auto bump = make_bumpmap_bsdf(diffuse.get(), test::ramp_texture(c.slope.x, c.slope.y));
    Vec3 n = tilted_normal(c.slope, c.dpdu, c.dpdv);
    // First case: atan(0.5) = 26.57 degrees towards -x.
    if (c.dpdu == Vec3(1, 0, 0) && c.slope.y == 0.f) {
      EXPECT_NEAR(std::acos(n.z) * 180.f / kPi, 26.565f, 1e-3f);
    }
    Vec3 wo = n;  // straight above the bumped surface
    Pcg32 rng(5);
    for (int i = 0; i < 200; ++i) {
      Vec3 wi = direction_deg(89.f * rng.next_float(), 360.f * rng.next_float());
      float expected = std::max(0.f, dot(wi, n)) * kInvPi;
      EXPECT_NEAR(bump->eval(si, wo, wi).g, expected, 1e-5f) << wi.x << " " << wi.y << " " << wi.z;
    }
  }
}

// The ramp's normal leans towards azimuth 207 degrees.
TEST(BumpMap, Chi2SamplingMatchesPdfOverATiltedFrame) {
  auto ramp = test::ramp_texture(0.5f, 0.25f);
  test::expect_tilted_chi2_passes([&](const Bsdf* nested) { return make_bumpmap_bsdf(nested, ramp); });
}

TEST(BumpMap, SampleWeightIsEvalOverPdf) {
  auto ramp = test::ramp_texture(0.5f, 0.25f);
  test::expect_tilted_weights_are_eval_over_pdf([&](const Bsdf* nested) { return make_bumpmap_bsdf(nested, ramp); },
                                                11);
}

// A cosine lobe about a normal tilted by alpha, clipped by the true horizon, keeps (1 + cos alpha)/2
// of its energy (the lost part projects onto half the disk minus half an ellipse of axes 1, cos
// alpha). So a white diffuse under a bump map never exceeds 1 and matches that fraction.
TEST(BumpMap, WhiteDiffuseAlbedoIsTheClippedLobe) {
  auto diffuse = test::white_diffuse(1.f);
  auto bump = make_bumpmap_bsdf(diffuse.get(), test::ramp_texture(0.5f, 0.f));
  SurfaceInteraction si = test::flat_si();
  test::expect_clipped_lobe_albedo(*bump, 180.f, 17, 0.5 * (1.0 + std::cos(std::atan(0.5))));
  // Seen from beyond the bumped horizon (wo above the surface, below the tilted normal).
  double mean, err;
  test::directional_albedo(*bump, si, direction_deg(80.f, 0.f), 20000, 17, mean, err);
  EXPECT_EQ(mean, 0.0);
}

TEST(BumpMap, ForwardsDeltaAndOpacity) {
  class HalfMask final : public Bsdf {
   public:
    Rgb eval(const SurfaceInteraction&, Vec3, Vec3) const override { return {}; }
    float pdf(const SurfaceInteraction&, Vec3, Vec3) const override { return 0.f; }
    bool sample(const SurfaceInteraction&, Vec3, float, Vec2, BsdfSample&) const override { return false; }
    bool is_delta() const override { return true; }
    bool has_opacity() const override { return true; }
    float opacity(const SurfaceInteraction& si) const override { return si.uv.x; }
  } mask;
  auto bump = make_bumpmap_bsdf(&mask, test::ramp_texture(0.5f, 0.f));
  EXPECT_TRUE(bump->is_delta());
  EXPECT_TRUE(bump->has_opacity());
  EXPECT_EQ(bump->opacity(test::flat_si({0.3f, 0.5f})), 0.3f);
  auto diffuse = test::white_diffuse();
  auto plain = make_bumpmap_bsdf(diffuse.get(), test::ramp_texture(0.5f, 0.f));
  EXPECT_FALSE(plain->is_delta());
  EXPECT_FALSE(plain->has_opacity());
}

std::shared_ptr<BitmapTexture> bad_texel_texture(float bad) {
  Image im(8, 8, 1);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) im.at(x, y, 0) = (x == 3 && y == 4) ? bad : 0.1f * float(x);
  return std::make_shared<BitmapTexture>(std::make_shared<const Image>(std::move(im)), WrapMode::Repeat,
                                         WrapMode::Repeat);
}

TEST(BumpMap, DegenerateInputsNeverGiveNaN) {
  auto diffuse = test::white_diffuse(0.8f);
  auto gold = test::rough_gold(0.3f);
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const Bsdf* nested : {diffuse.get(), gold.get()}) {
    auto ramp = make_bumpmap_bsdf(nested, test::ramp_texture(0.5f, 0.25f));
    SurfaceInteraction si = test::flat_si();
    si.dpdu = si.dpdv = Vec3(0.f);  // zero dp/du: the unperturbed frame stands in
    expect_finite_everywhere(*ramp, si, 23, 300, "zero dpdu");
    Vec3 wo = direction_deg(30.f, 10.f), wi = direction_deg(50.f, 200.f);
    EXPECT_EQ(ramp->eval(si, wo, wi), nested->eval(si, wo, wi));
    si.dpdu = si.dpdv = Vec3(1.f, 0.f, 0.f);  // collinear
    expect_finite_everywhere(*ramp, si, 23, 300, "collinear dpdu dpdv");
    si.dpdu = Vec3(1e30f, 0.f, 0.f);  // overflowing cross product
    si.dpdv = Vec3(0.f, 1e30f, 0.f);
    expect_finite_everywhere(*ramp, si, 23, 300, "huge dpdu");
    si = test::flat_si({nan, 0.5f});
    expect_finite_everywhere(*ramp, si, 23, 300, "NaN uv");
    for (float bad : {nan, inf, -inf, 1e38f}) {
      auto b = make_bumpmap_bsdf(nested, bad_texel_texture(bad));
      for (float u : {0.375f, 0.45f, 0.5f, 0.55f}) {
        SurfaceInteraction s = test::flat_si({u, 0.5625f});
        expect_finite_everywhere(*b, s, 23, 300, "bad texel");
      }
    }
  }
}

// dp/du and dp/dv of the shapes: from the triangle's uvs, analytic on the sphere, an orthonormal
// tangent pair of ng when the parameterisation is degenerate or missing.
SurfaceInteraction hit_triangle(const MeshData& m, float b1, float b2) {
  TriangleMeshShape shape(std::make_shared<const MeshData>(m), false, false);
  Ray ray{Vec3(0.3f, 0.3f, 5.f), Vec3(0.f, 0.f, -1.f)};
  Hit hit{5.f, 0, b1, b2};
  SurfaceInteraction si;
  shape.fill_interaction(ray, hit, 0, si);
  return si;
}

void expect_tangent_pair(const SurfaceInteraction& si) {
  EXPECT_NEAR(length(si.dpdu), 1.f, 1e-5f);
  EXPECT_NEAR(length(si.dpdv), 1.f, 1e-5f);
  EXPECT_NEAR(dot(si.dpdu, si.dpdv), 0.f, 1e-5f);
  EXPECT_NEAR(dot(si.dpdu, si.ng), 0.f, 1e-5f);
  EXPECT_NEAR(dot(si.dpdv, si.ng), 0.f, 1e-5f);
}

TEST(BumpMapGeometry, TriangleDerivativesFromUvs) {
  MeshData m;
  m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 3, 0}};
  m.indices = {0, 1, 2};
  m.uvs = {{0, 0}, {1, 0}, {0, 1}};
  SurfaceInteraction si = hit_triangle(m, 0.2f, 0.3f);
  EXPECT_NEAR(si.dpdu.x, 2.f, 1e-6f);
  EXPECT_NEAR(length(si.dpdu - Vec3(2, 0, 0)), 0.f, 1e-6f);
  EXPECT_NEAR(length(si.dpdv - Vec3(0, 3, 0)), 0.f, 1e-6f);
  // Rotated, mirrored uvs: dp/du follows them.
  m.uvs = {{1, 1}, {1, 0}, {0, 1}};  // u decreases along +y, v decreases along +x
  si = hit_triangle(m, 0.2f, 0.3f);
  EXPECT_NEAR(length(si.dpdu - Vec3(0, -3, 0)), 0.f, 1e-5f);
  EXPECT_NEAR(length(si.dpdv - Vec3(-2, 0, 0)), 0.f, 1e-5f);
  m.uvs = {{0.5f, 0.5f}, {0.5f, 0.5f}, {0.5f, 0.5f}};  // zero determinant
  expect_tangent_pair(hit_triangle(m, 0.2f, 0.3f));
  m.uvs = {{0, 0}, {1, 1}, {2, 2}};  // collinear uvs
  expect_tangent_pair(hit_triangle(m, 0.2f, 0.3f));
  m.uvs.clear();
  expect_tangent_pair(hit_triangle(m, 0.2f, 0.3f));
}

TEST(BumpMapGeometry, SphereDerivativesAreAnalytic) {
  SphereShape sphere(Vec3(1.f, 2.f, 3.f), 2.f, false);
  SurfaceInteraction si;
  Ray ray{Vec3(6.f, 2.5f, 3.5f), normalize(Vec3(-1.f, 0.f, 0.f))};
  sphere.fill_interaction(ray, Hit{5.f - std::sqrt(4.f - 0.5f), 0, 0.f, 0.f}, 0, si);
  // Finite differences of the spherical map p(u, v) = c + r (sin pi v cos 2pi u, ..., cos pi v).
  auto p_of = [](float u, float v) {
    float th = kPi * v, ph = 2.f * kPi * u;
    return Vec3(1.f, 2.f, 3.f) + Vec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)) * 2.f;
  };
  const float h = 1e-3f;
  Vec3 fd_u = (p_of(si.uv.x + h, si.uv.y) - p_of(si.uv.x - h, si.uv.y)) / (2.f * h);
  Vec3 fd_v = (p_of(si.uv.x, si.uv.y + h) - p_of(si.uv.x, si.uv.y - h)) / (2.f * h);
  EXPECT_LT(length(si.dpdu - fd_u), 2e-2f * length(fd_u));
  EXPECT_LT(length(si.dpdv - fd_v), 2e-2f * length(fd_v));
  // At a pole any tangent pair of ng.
  sphere.fill_interaction(Ray{Vec3(1.f, 2.f, 10.f), Vec3(0.f, 0.f, -1.f)}, Hit{5.f, 0, 0.f, 0.f}, 0, si);
  expect_tangent_pair(si);
}

}  // namespace
}  // namespace tessera
