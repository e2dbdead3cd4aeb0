#include "tessera/light/directional.h"

#include "light/emitter_sample.h"

#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

class DirectionalLight final : public Light {
 public:
  DirectionalLight(Vec3 direction, Rgb irradiance) : wi_(-normalize(direction)), irradiance_(irradiance) {}

  void preprocess(const Bounds3& scene_bounds) override {
    center_ = scene_bounds.empty() ? Vec3(0.f) : scene_bounds.center();
    radius_ = scene_bounds.empty() ? 0.f : 0.5f * length(scene_bounds.diagonal());
  }

  bool sample_li(Vec3 ref_p, Vec2, LightSample& out) const override {
    // A point beyond the scene along wi, for callers that want one; shadow rays use dist = infinity.
    const float r = std::max({radius_, length(ref_p - center_), 1e-3f});
    out.li = irradiance_;
    out.wi = wi_;
    out.p_light = ref_p + wi_ * (2.f * r);
    out.n_light = Vec3(0.f);
    out.dist = kInfinity;
    out.pdf = 1.f;
    out.delta = true;
    return true;
  }

  // Emission: the one direction of travel, from a point uniform on the disk that covers the scene's
  // cross-section; le / pdf_pos = E pi R^2, the power.
  bool sample_le(Vec2 u_pos, Vec2, LightEmission& out) const override {
    if (irradiance_.is_black()) return false;
    if (!detail::EmissionDisk{center_, radius_}.sample(-wi_, u_pos, out)) return false;
    out.le = irradiance_;
    out.pdf_dir = 1.f;
    out.delta_dir = true;
    return true;
  }

  void pdf_le(Vec3, Vec3, Vec3, float& pdf_pos, float& pdf_dir) const override {
    pdf_pos = detail::EmissionDisk{center_, radius_}.pdf_pos();
    pdf_dir = 1.f;
  }

  bool is_delta() const override { return true; }
  bool is_distant() const override { return true; }
  float power() const override {
    const float r = radius_ > 0.f ? radius_ : 1.f;
    return kPi * r * r * irradiance_.luminance();
  }

 private:
  Vec3 wi_;
  Rgb irradiance_;
  Vec3 center_;
  float radius_ = 0.f;
};

}  // namespace

std::unique_ptr<Light> make_directional_light(Vec3 direction, Rgb irradiance) {
  return std::make_unique<DirectionalLight>(direction, irradiance);
}

// Mitsuba 0.6 and 3: `direction`, or else to_world applied to +z; `irradiance` defaults to white 1
// (D65 reduced to RGB). Giving both `direction` and `to_world` is an error, as in Mitsuba.
std::unique_ptr<Light> make_directional(const SceneNode& node, LoadContext& ctx) {
  Vec3 direction;
  if (node.has("direction")) {
    if (node.has("to_world"))
      throw SceneError(node.loc, node.describe() + ": give either 'direction' or 'to_world', not both");
    const Property* p = node.find("direction");
    direction = node.get_vector("direction", Vec3(0.f, 0.f, 1.f));
    if (!(length(direction) > 0.f) || !std::isfinite(length(direction)))
      throw SceneError(p->loc, node.describe() + ": 'direction' must be a non-zero vector");
  } else {
    direction = node.get_transform("to_world", Transform()).apply_vector(Vec3(0.f, 0.f, 1.f));
    if (!(length(direction) > 0.f))
      throw SceneError(node.loc, node.describe() + ": to_world maps +z to a zero vector");
  }
  const Rgb irradiance = node.get_color("irradiance", Rgb(1.f));
  if (!irradiance.is_finite() || irradiance.r < 0.f || irradiance.g < 0.f || irradiance.b < 0.f)
    throw SceneError(node.loc, node.describe() + ": irradiance must be finite and non-negative");
  return make_directional_light(direction, irradiance);
}

}  // namespace tessera
