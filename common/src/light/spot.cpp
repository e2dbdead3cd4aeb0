// Mitsuba's `spot` emitter: a delta-position light with a cone profile.
//
// Mitsuba 0.6 (src/emitters/spot.cpp) and Mitsuba 3 share the profile: full intensity inside the
// beam, a ramp LINEAR IN THE ANGLE from the beam width to the cutoff, nothing beyond. (pbrt-v4's
// spot uses a smoothstep in cos theta instead; scenes written for Mitsuba expect the linear ramp.)
// The projection texture, when given, multiplies the intensity at uv = 0.5 + 0.5 (x, y) / (z tan
// cutoff). Mitsuba 0.6 ignores a constant `texture` (only non-constant textures are looked up) and
// Mitsuba 3 rejects one; Tessera ignores it with a note.
#include "tessera/light/spot.h"

#include "light/emitter_sample.h"

#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/render/light_bounds.h"
#include "tessera/scene/load_context.h"

#include <cmath>

namespace tessera {
namespace {

constexpr double kPiD = 3.14159265358979323846;

class SpotLight final : public Light {
 public:
  SpotLight(const Transform& world_from_light, Rgb intensity, float cutoff_degrees, float beam_degrees,
            std::shared_ptr<const Texture> texture)
      : light_from_world_(world_from_light.inverse()), intensity_(intensity), texture_(std::move(texture)) {
    TESSERA_CHECK(cutoff_degrees > 0.f && cutoff_degrees <= 180.f);
    TESSERA_CHECK(beam_degrees >= 0.f && beam_degrees <= cutoff_degrees);
    TESSERA_CHECK(!texture_ || cutoff_degrees < 90.f);
    position_ = world_from_light.apply_point(Vec3(0.f));
    axis_ = normalize(world_from_light.apply_vector(Vec3(0.f, 0.f, 1.f)));
    double cutoff = double(cutoff_degrees) * kPiD / 180.0, beam = double(beam_degrees) * kPiD / 180.0;
    cutoff_ = float(cutoff);
    cos_cutoff_ = float(std::cos(cutoff));
    cos_beam_ = float(std::cos(beam));
    inv_transition_ = cutoff > beam ? float(1.0 / (cutoff - beam)) : 0.f;
    uv_factor_ = texture_ ? float(std::tan(cutoff)) : 1.f;
    double solid_angle = spot_profile_solid_angle(cutoff, beam);
    double scale = double(intensity_.luminance()) * (texture_ ? double(texture_->mean().luminance()) : 1.0);
    power_ = float(solid_angle * scale);
    bounds_phi_ = float(4.0 * kPiD * scale);
    cos_beam_spread_ = float(std::cos(cutoff - beam));
    // The cone sample_le draws from ends at the float cos_cutoff_; its solid angle in double, since
    // for narrow spots 1 - cos loses its digits in float. 0 (no emission sampling) for a cutoff
    // too narrow for float to tell from the axis.
    const double inv_cone = 1.0 / (2.0 * kPiD * (1.0 - double(cos_cutoff_)));
    inv_cone_solid_angle_ = std::isfinite(float(inv_cone)) ? float(inv_cone) : 0.f;
  }

  bool sample_li(Vec3 ref_p, Vec2, LightSample& out) const override {
    if (!detail::point_emitter_sample(position_, ref_p, out)) return false;
    // Emission direction (light -> reference point) in light space; normalised so that a scale in
    // to_world does not distort the profile.
    Vec3 local = normalize(light_from_world_.apply_vector(-out.wi));
    Rgb profile = eval_profile(local);
    if (profile.is_black()) return false;
    out.li *= profile;
    return true;
  }

  // Emission: directions uniform in the cone of the cutoff (the spot's total width) around its
  // axis, weighted by the profile; le / pdf_dir then averages to the power over that cone.
  bool sample_le(Vec2, Vec2 u_dir, LightEmission& out) const override {
    if (!(power_ > 0.f)) return false;
    out.dir = normalize(Frame(axis_).to_world(square_to_uniform_cone(u_dir, cos_cutoff_)));
    out.le = eval_profile(normalize(light_from_world_.apply_vector(out.dir)));
    if (out.le.is_black()) return false;
    out.p = position_;
    out.n = Vec3(0.f);
    out.p_error = Vec3(0.f);
    out.pdf_pos = 1.f;
    out.pdf_dir = cone_pdf(out.dir);
    out.delta_pos = true;
    out.delta_dir = out.infinite = false;
    return out.pdf_dir > 0.f;
  }

  void pdf_le(Vec3, Vec3, Vec3 dir, float& pdf_pos, float& pdf_dir) const override {
    pdf_pos = 1.f;
    pdf_dir = cone_pdf(dir);
  }

  bool is_delta() const override { return true; }
  float power() const override { return power_; }

  // For light hierarchies, as pbrt-v4's spot: full intensity within the beam (theta_o), falling to
  // 0 over cutoff - beam (theta_e). phi is 4 pi I, not power(): a hierarchy weighs phi / d^2 as it
  // does for point lights (power 4 pi I), so a spot is as important inside its beam as a point of
  // the same intensity, and the cone alone takes it out of the picture elsewhere.
  bool light_bounds(LightBounds& out) const override {
    out.bounds = Bounds3();
    out.bounds.extend(position_);
    out.w = axis_;
    out.phi = bounds_phi_;
    out.cos_theta_o = cos_beam_;
    out.cos_theta_e = cos_beam_spread_;
    out.two_sided = false;
    return out.phi > 0.f;
  }

 private:
  /// Radiant intensity towards the unit light-space direction `d`.
  Rgb eval_profile(Vec3 d) const {
    float cos_theta = d.z;
    if (cos_theta <= cos_cutoff_) return {};
    Rgb result = intensity_;
    if (texture_) {
      SurfaceInteraction si;
      si.p = position_;
      si.uv = Vec2(0.5f + 0.5f * d.x / (d.z * uv_factor_), 0.5f + 0.5f * d.y / (d.z * uv_factor_));
      result = result * texture_->eval(si);
    }
    if (cos_theta >= cos_beam_) return result;
    return result * ((cutoff_ - std::acos(cos_theta)) * inv_transition_);
  }

  /// Solid-angle density of sample_le's uniform cone. The cone is built around the world axis, so
  /// to_world must be rigid (up to uniform scale), as a look_at is, for it to match the profile.
  float cone_pdf(Vec3 dir) const {
    if (!(dot(dir, axis_) >= cos_cutoff_)) return 0.f;
    return inv_cone_solid_angle_;
  }

  Transform light_from_world_;
  Vec3 position_, axis_;
  Rgb intensity_;
  std::shared_ptr<const Texture> texture_;
  float cutoff_, cos_cutoff_, cos_beam_, inv_transition_, uv_factor_;
  float power_, bounds_phi_, cos_beam_spread_, inv_cone_solid_angle_;
};

}  // namespace

double spot_profile_solid_angle(double cutoff, double beam) {
  // 2 pi [ int_0^beam sin + int_beam^cutoff (cutoff - t) / (cutoff - beam) sin t dt ]
  if (!(cutoff > beam)) return 2.0 * kPiD * (1.0 - std::cos(cutoff));
  return 2.0 * kPiD * (1.0 + (std::sin(beam) - std::sin(cutoff)) / (cutoff - beam));
}

std::unique_ptr<Light> make_spot_light(const Transform& world_from_light, Rgb intensity, float cutoff_degrees,
                                       float beam_width_degrees, std::shared_ptr<const Texture> texture) {
  return std::make_unique<SpotLight>(world_from_light, intensity, cutoff_degrees, beam_width_degrees,
                                     std::move(texture));
}

// Mitsuba 0.6 `cutoffAngle`, `beamWidth`, `intensity`, `texture`, `toWorld` (Mitsuba 3: the same
// in snake_case). Neither version takes `position`/`target`: orient with a lookat in to_world.
std::unique_ptr<Light> make_spot(const SceneNode& node, LoadContext& ctx) {
  Transform to_world = node.get_transform("to_world", Transform());
  Rgb intensity = node.get_color("intensity", Rgb(1.f));
  const Property* cutoff_p = node.find("cutoff_angle");
  float cutoff = node.get_float("cutoff_angle", 20.f);
  if (!(cutoff > 0.f && cutoff <= 180.f))
    throw SceneError(cutoff_p ? cutoff_p->loc : node.loc, node.describe() + ": cutoff_angle must be in (0, 180] degrees");
  const Property* beam_p = node.find("beam_width");
  float beam = node.get_float("beam_width", cutoff * 0.75f);
  if (!(beam >= 0.f && beam <= cutoff))
    throw SceneError(beam_p ? beam_p->loc : node.loc,
                     node.describe() + ": beam_width must be in [0, cutoff_angle] degrees");
  std::shared_ptr<const Texture> texture = ctx.texture(node, "texture", Rgb(1.f));
  if (dynamic_cast<const ConstantTexture*>(texture.get())) {
    if (node.peek("texture"))
      ctx.note(node.peek("texture")->loc, node.describe() + ": a constant 'texture' is ignored (as in Mitsuba 0.6); "
                                                            "use 'intensity' for the colour");
    texture = nullptr;
  }
  if (texture && !(cutoff < 90.f))
    throw SceneError(cutoff_p ? cutoff_p->loc : node.loc,
                     node.describe() + ": a projected texture needs cutoff_angle < 90 degrees");
  return make_spot_light(to_world, intensity, cutoff, beam, std::move(texture));
}

}  // namespace tessera
