// spot light: the intensity profile against Mitsuba 0.6's formula, its projection texture, power()
// against a numerical integral of the profile, the factory's parameters and defaults.
//
// No chi-square test here: sample_li() of a spot is a delta (one direction, pdf 1), so the profile
// the integrators see is checked value by value instead. Its emission sampling (sample_le, a
// uniform cone) is tested with every other emitter's in emission_direction_test.cpp.
#include "tessera/render/light_bounds.h"
#include "tessera/light/spot.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tessera {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

// Mitsuba 0.6's SpotEmitter::falloffCurve, written out from its definition (angles in radians).
double mitsuba_falloff(double theta, double cutoff, double beam) {
  if (std::cos(theta) <= std::cos(cutoff)) return 0.0;
  if (std::cos(theta) >= std::cos(beam)) return 1.0;
  return (cutoff - theta) / (cutoff - beam);
}

Transform light_frame() {
  // Spot at (1, 2, 3) aimed at (-1, 0.5, 0): an oblique axis tests the world -> light rotation.
  return *Transform::look_at({1.f, 2.f, 3.f}, {-1.f, 0.5f, 0.f}, {0.f, 0.f, 1.f});
}

Vec3 light_dir(double theta, double phi) {
  return Vec3(float(std::sin(theta) * std::cos(phi)), float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)));
}

TEST(SpotLight, ProfileMatchesMitsubaFormula) {
  const Transform xf = light_frame();
  const Vec3 pos = xf.apply_point(Vec3(0.f));
  struct Case {
    float cutoff, beam;
  };
  for (Case c : {Case{30.f, 20.f}, Case{20.f, 15.f}, Case{60.f, 0.f}, Case{10.f, 10.f}, Case{120.f, 45.f}}) {
    auto light = make_spot_light(xf, Rgb(2.f, 3.f, 4.f), c.cutoff, c.beam);
    EXPECT_TRUE(light->is_delta());
    int inside = 0, ramp = 0, outside = 0;
    for (int i = 0; i <= 200; ++i) {
      double theta = (double(c.cutoff) * 1.3) * kDeg * i / 200.0 + 1e-4;
      for (double phi : {0.3, 2.1, 4.4}) {
        const float dist = 1.7f;
        Vec3 w = normalize(xf.apply_vector(light_dir(theta, phi)));
        Vec3 ref = pos + w * dist;
        LightSample ls;
        bool ok = light->sample_li(ref, {0.5f, 0.5f}, ls);
        double f = mitsuba_falloff(theta, c.cutoff * kDeg, c.beam * kDeg);
        // The angle to the cone edge below float resolution: either answer is right.
        if (std::abs(theta - c.cutoff * kDeg) < 1e-5 || std::abs(theta - c.beam * kDeg) < 1e-5) continue;
        if (f == 0.0) {
          ++outside;
          EXPECT_FALSE(ok && !ls.li.is_black()) << "theta " << theta / kDeg;
          continue;
        }
        (f == 1.0 ? inside : ramp) += 1;
        ASSERT_TRUE(ok) << "theta " << theta / kDeg;
        EXPECT_TRUE(ls.delta);
        EXPECT_EQ(ls.pdf, 1.f);
        EXPECT_NEAR(ls.dist, dist, 1e-5f);
        EXPECT_NEAR(length(ls.wi + w), 0.f, 1e-5f);  // towards the light
        EXPECT_EQ(ls.p_light, pos);
        // In float, the angle recovered from a direction near the axis is good to ~1e-6 / sin(theta)
        // radians (cos theta is within a few ulps of 1): accept the profile over that interval.
        double eps = 1e-6 / std::max(std::sin(theta), 1e-3);
        double f_lo = mitsuba_falloff(theta + eps, c.cutoff * kDeg, c.beam * kDeg);
        double f_hi = mitsuba_falloff(std::max(theta - eps, 0.0), c.cutoff * kDeg, c.beam * kDeg);
        for (int ch = 0; ch < 3; ++ch) {
          double scale = double(Rgb(2.f, 3.f, 4.f)[ch]) / (double(dist) * dist);
          EXPECT_GE(ls.li[ch], scale * f_lo * (1 - 2e-5) - 1e-6)
              << "cutoff " << c.cutoff << " beam " << c.beam << " theta " << theta / kDeg << " f " << f;
          EXPECT_LE(ls.li[ch], scale * f_hi * (1 + 2e-5) + 1e-6)
              << "cutoff " << c.cutoff << " beam " << c.beam << " theta " << theta / kDeg << " f " << f;
        }
      }
    }
    if (c.beam > 0.f) {
      EXPECT_GT(inside, 0);
    }
    EXPECT_GT(outside, 0);
    if (c.cutoff > c.beam) {
      EXPECT_GT(ramp, 0);
    }
  }
}

// Irradiance on a plane facing the light: E = I f(theta) cos(theta) / d^2 (with the plane's
// cosine), from sample_li() as an integrator uses it.
TEST(SpotLight, IrradianceOnPlane) {
  const float h = 2.f;
  auto xf = *Transform::look_at({0.f, 0.f, h}, {0.f, 0.f, 0.f}, {0.f, 1.f, 0.f});
  auto light = make_spot_light(xf, Rgb(5.f), 40.f, 25.f);
  const Vec3 n(0.f, 0.f, 1.f);
  for (int i = 0; i < 60; ++i) {
    double r = 2.2 * i / 59.0, phi = 0.7 * i;
    Vec3 p(float(r * std::cos(phi)), float(r * std::sin(phi)), 0.f);
    double d2 = r * r + double(h) * h, theta = std::atan2(r, double(h)), cos_plane = h / std::sqrt(d2);
    double expected = 5.0 * mitsuba_falloff(theta, 40 * kDeg, 25 * kDeg) * cos_plane / d2;
    LightSample ls;
    double e = light->sample_li(p, {}, ls) ? double(ls.li.g) * std::max(0.f, dot(ls.wi, n)) : 0.0;
    EXPECT_NEAR(e, expected, 2e-5 * expected + 1e-7) << "r " << r;
  }
}

// power() = integral of the intensity profile over the sphere; here by the midpoint rule in theta
// (and a few phi, since the profile is symmetric) over what sample_li() returns.
TEST(SpotLight, PowerIsIntegralOfProfile) {
  const Transform xf = light_frame();
  const Vec3 pos = xf.apply_point(Vec3(0.f));
  for (auto [cutoff, beam] : {std::pair{20.f, 15.f}, {45.f, 10.f}, {90.f, 60.f}, {30.f, 30.f}, {170.f, 5.f}}) {
    const Rgb intensity(1.f, 2.f, 0.5f);
    auto light = make_spot_light(xf, intensity, cutoff, beam);
    const int n_theta = 20000;
    double integral = 0;
    for (int i = 0; i < n_theta; ++i) {
      double theta = kDeg * 180.0 * (i + 0.5) / n_theta, dtheta = kDeg * 180.0 / n_theta;
      double ring = 0;
      for (double phi : {0.1, 1.9, 3.3, 5.0}) {
        LightSample ls;
        Vec3 ref = pos + normalize(xf.apply_vector(light_dir(theta, phi))) * 3.f;
        if (light->sample_li(ref, {}, ls)) ring += double(ls.li.luminance()) * 9.0 / 4.0;  // I = li d^2
      }
      integral += ring * 2.0 * 3.14159265358979323846 * std::sin(theta) * dtheta;
    }
    EXPECT_NEAR(light->power(), integral, 2e-4 * integral) << "cutoff " << cutoff << " beam " << beam;
    EXPECT_NEAR(spot_profile_solid_angle(cutoff * kDeg, beam * kDeg) * intensity.luminance(), integral,
                2e-4 * integral);
  }
  // No ramp: a uniform cone, 2 pi (1 - cos cutoff).
  EXPECT_NEAR(spot_profile_solid_angle(0.5, 0.5), 2 * 3.14159265358979323846 * (1 - std::cos(0.5)), 1e-12);
}

// A texture that returns its lookup coordinates, to check the projection.
class UvTexture final : public Texture {
 public:
  Rgb eval(const SurfaceInteraction& si) const override { return {si.uv.x, si.uv.y, 1.f}; }
  Rgb mean() const override { return {0.5f, 0.5f, 1.f}; }
};

TEST(SpotLight, TextureProjectedThroughCone) {
  const float cutoff = 35.f, beam = 30.f;
  auto light = make_spot_light(Transform(), Rgb(2.f), cutoff, beam, std::make_shared<UvTexture>());
  const double t = std::tan(cutoff * kDeg);
  for (Vec3 d : {Vec3(0.f, 0.f, 1.f), Vec3(0.3f, 0.1f, 1.f), Vec3(-0.2f, 0.45f, 1.f), Vec3(0.6f, -0.2f, 1.f)}) {
    Vec3 w = normalize(d);
    LightSample ls;
    ASSERT_TRUE(light->sample_li(w * 2.f, {}, ls));
    double theta = std::acos(double(w.z));
    double f = mitsuba_falloff(theta, cutoff * kDeg, beam * kDeg) * 2.0 / 4.0;  // I f / d^2
    double u = 0.5 + 0.5 * w.x / (w.z * t), v = 0.5 + 0.5 * w.y / (w.z * t);
    EXPECT_NEAR(ls.li.r, u * f, 1e-5);
    EXPECT_NEAR(ls.li.g, v * f, 1e-5);
    EXPECT_NEAR(ls.li.b, f, 1e-5);
  }
  // The cutoff circle touches the edges of the unit uv square.
  LightSample ls;
  Vec3 edge = light_dir((cutoff - 1e-3) * kDeg, 0.0);
  ASSERT_TRUE(light->sample_li(edge, {}, ls));
  EXPECT_NEAR(ls.li.r / ls.li.b, 1.0, 1e-3);
  // power() scales by the texture's mean.
  auto plain = make_spot_light(Transform(), Rgb(2.f), cutoff, beam);
  EXPECT_NEAR(light->power(), plain->power() * Rgb(0.5f, 0.5f, 1.f).luminance(), 1e-4 * plain->power());
}

std::unique_ptr<Scene> load(const std::string& emitter) {
  LoadOptions o;
  o.width = 8;
  o.height = 8;
  auto desc = parse_scene_string("<scene version=\"0.6.0\">" + emitter + "<shape type=\"sphere\"/></scene>", "mem/spot.xml");
  return load_scene(desc, o).scene;
}

TEST(SpotLight, FactoryDefaultsAndParameters) {
  // Mitsuba 0.6 spelling; beamWidth defaults to 3/4 of cutoffAngle (here 30 degrees).
  auto scene = load(R"(<emitter type="spot"><float name="cutoffAngle" value="40"/><rgb name="intensity" value="3"/>
                       <transform name="toWorld"><translate z="-2"/></transform></emitter>)");
  ASSERT_EQ(scene->lights.size(), 1u);
  const Light& spot = *scene->lights[0];
  auto li_at = [&](double theta_deg) {
    LightSample ls;
    bool ok = spot.sample_li(Vec3(0.f, 0.f, -2.f) + light_dir(theta_deg * kDeg, 0.4) * 2.f, {}, ls);
    return ok ? double(ls.li.r) * 4.0 : 0.0;
  };
  EXPECT_NEAR(li_at(29.0), 3.0, 1e-5);
  EXPECT_NEAR(li_at(35.0), 1.5, 1e-4);
  EXPECT_NEAR(li_at(39.0), 0.3, 1e-4);
  EXPECT_EQ(li_at(41.0), 0.0);
  // All defaults: intensity 1, cutoff 20, beam 15, at the origin looking down +z.
  auto dflt = load(R"(<emitter type="spot"/>)");
  LightSample ls;
  ASSERT_TRUE(dflt->lights[0]->sample_li(light_dir(17.5 * kDeg, 1.0), {}, ls));
  EXPECT_NEAR(ls.li.g, 0.5f, 1e-4f);
  EXPECT_FALSE(dflt->lights[0]->sample_li(light_dir(20.5 * kDeg, 1.0), {}, ls));
  EXPECT_NEAR(dflt->lights[0]->power(), spot_profile_solid_angle(20 * kDeg, 15 * kDeg), 1e-5);

  // Mitsuba 3 spelling, and a constant `texture`, which Mitsuba 0.6 ignores (not multiplied).
  auto v3 = load(R"(<emitter type="spot"><float name="cutoff_angle" value="30"/><float name="beam_width" value="10"/>
                    <rgb name="texture" value="0.25"/></emitter>)");
  ASSERT_TRUE(v3->lights[0]->sample_li(light_dir(20 * kDeg, 0.0), {}, ls));
  EXPECT_NEAR(ls.li.r, 0.5f, 1e-4f);

  EXPECT_THROW(load(R"(<emitter type="spot"><float name="cutoffAngle" value="10"/><float name="beamWidth" value="12"/></emitter>)"),
               SceneError);
  EXPECT_THROW(load(R"(<emitter type="spot"><float name="cutoffAngle" value="-5"/></emitter>)"), SceneError);
  // A projected texture needs the cone to stay in front of the light.
  EXPECT_THROW(load(R"(<emitter type="spot"><float name="cutoffAngle" value="95"/>
                       <texture name="texture" type="checkerboard"/></emitter>)"),
               SceneError);
}

// Light-hierarchy bounds: a point with the cone of the beam (theta_o) widened by the ramp
// (theta_e); importance vanishes only where the spot cannot shine.
TEST(SpotLight, LightBoundsCoverTheCone) {
  const Transform xf = light_frame();
  const float cutoff = 30.f, beam = 20.f;
  auto light = make_spot_light(xf, Rgb(2.f), cutoff, beam);
  LightBounds lb;
  ASSERT_TRUE(light->light_bounds(lb));
  const Vec3 pos = xf.apply_point(Vec3(0.f)), axis = normalize(xf.apply_vector({0.f, 0.f, 1.f}));
  EXPECT_EQ(lb.bounds.lo, pos);
  EXPECT_EQ(lb.bounds.hi, pos);
  EXPECT_NEAR(length(lb.w - axis), 0.f, 1e-6f);
  EXPECT_NEAR(lb.cos_theta_o, std::cos(beam * kDeg), 1e-6);
  EXPECT_NEAR(lb.cos_theta_e, std::cos((cutoff - beam) * kDeg), 1e-6);
  EXPECT_NEAR(lb.phi, 4 * 3.14159265358979323846 * Rgb(2.f).luminance(), 1e-4);
  for (int i = 0; i <= 40; ++i) {
    double theta = 60.0 * kDeg * i / 40.0;
    Vec3 p = pos + normalize(xf.apply_vector(light_dir(theta, 1.3))) * 2.f;
    LightSample ls;
    bool lit = light->sample_li(p, {}, ls);
    float imp = lb.importance(p, Vec3(0.f));  // in a medium: no cosine at p
    if (lit) {
      EXPECT_GT(imp, 0.f) << "theta " << theta / kDeg;
    }
    if (theta > (cutoff + 0.5) * kDeg) {
      EXPECT_EQ(imp, 0.f) << "theta " << theta / kDeg;
    }
  }
}

}  // namespace
}  // namespace tessera
