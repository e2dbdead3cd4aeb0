// Isotropic point light: a delta in position, emitting the same intensity in every direction.
#include "tessera/light/point.h"

#include "light/emitter_sample.h"

#include "tessera/core/sampling.h"
#include "tessera/render/light_bounds.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class PointLight final : public Light {
 public:
  PointLight(Vec3 position, Rgb intensity) : position_(position), intensity_(intensity) {}

  bool sample_li(Vec3 ref_p, Vec2, LightSample& out) const override {
    if (!detail::point_emitter_sample(position_, ref_p, out)) return false;
    out.li *= intensity_;
    return true;
  }

  // Emission: uniform over the sphere of directions, so le / pdf_dir = 4 pi I, the power.
  bool sample_le(Vec2, Vec2 u_dir, LightEmission& out) const override {
    if (intensity_.is_black()) return false;
    out.p = position_;
    out.n = Vec3(0.f);
    out.p_error = Vec3(0.f);
    out.dir = square_to_uniform_sphere(u_dir);
    out.le = intensity_;
    out.pdf_pos = 1.f;
    out.pdf_dir = kInv4Pi;
    out.delta_pos = true;
    out.delta_dir = out.infinite = false;
    return true;
  }

  void pdf_le(Vec3, Vec3, Vec3, float& pdf_pos, float& pdf_dir) const override {
    pdf_pos = 1.f;
    pdf_dir = kInv4Pi;
  }

  bool is_delta() const override { return true; }
  float power() const override { return 4.f * kPi * intensity_.luminance(); }

  // A point emitting in every direction: any axis, theta_o = pi.
  bool light_bounds(LightBounds& out) const override {
    out.bounds = Bounds3();
    out.bounds.extend(position_);
    out.w = Vec3(0.f, 0.f, 1.f);
    out.phi = power();
    out.cos_theta_o = -1.f;
    out.cos_theta_e = 0.f;
    out.two_sided = false;
    return out.phi > 0.f;
  }

 private:
  Vec3 position_;
  Rgb intensity_;
};

}  // namespace

std::unique_ptr<Light> make_point_light(Vec3 position, Rgb intensity) {
  return std::make_unique<PointLight>(position, intensity);
}

// Mitsuba 0.6 and 3: `position`, or else the translation of `to_world`; `intensity` defaults to
// white 1 (D65 reduced to RGB).
std::unique_ptr<Light> make_point(const SceneNode& node, LoadContext& ctx) {
  Vec3 position;
  if (node.has("position")) {
    if (node.has("to_world"))
      throw SceneError(node.loc, node.describe() + ": give either 'position' or 'to_world', not both");
    position = node.get_vector("position", Vec3(0.f));
  } else {
    position = node.get_transform("to_world", Transform()).apply_point(Vec3(0.f));
  }
  Rgb intensity = node.get_color("intensity", Rgb(1.f));
  return make_point_light(position, intensity);
}

}  // namespace tessera
