// Mitsuba's `constant` emitter (light/constant.h).
#include "tessera/light/constant.h"

#include "light/emitter_sample.h"

#include "tessera/core/sampling.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <memory>

namespace tessera {

void ConstantLight::preprocess(const Bounds3& scene_bounds) {
  center_ = scene_bounds.empty() ? Vec3(0.f) : scene_bounds.center();
  radius_ = scene_bounds.empty() ? 0.f : 0.5f * length(scene_bounds.diagonal());
}

bool ConstantLight::sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const {
  Vec3 wi = square_to_uniform_sphere(u);
  // A point beyond the scene, for callers that want one; shadow rays use dist = infinity.
  float r = std::max({radius_, length(ref_p - center_), 1e-3f});
  out.li = radiance_;
  out.wi = wi;
  out.p_light = ref_p + wi * (2.f * r);
  out.n_light = Vec3(0.f);
  out.dist = kInfinity;
  out.pdf = kInv4Pi;
  out.delta = false;
  return true;
}

// Emission: directions uniform over the sphere, as sample_li draws them, from the disk facing each.
bool ConstantLight::sample_le(Vec2 u_pos, Vec2 u_dir, LightEmission& out) const {
  if (radiance_.is_black()) return false;
  if (!detail::EmissionDisk{center_, radius_}.sample(square_to_uniform_sphere(u_dir), u_pos, out)) return false;
  out.le = radiance_;
  out.pdf_dir = kInv4Pi;
  out.delta_dir = false;
  return true;
}

void ConstantLight::pdf_le(Vec3, Vec3, Vec3, float& pdf_pos, float& pdf_dir) const {
  pdf_pos = detail::EmissionDisk{center_, radius_}.pdf_pos();
  pdf_dir = kInv4Pi;
}

float ConstantLight::power() const {
  float r = radius_ > 0.f ? radius_ : 1.f;
  return 4.f * kPi * kPi * r * r * radiance_.luminance();
}

/// Mitsuba's `constant`: `radiance` (colour or float, default 1).
std::unique_ptr<Light> make_constant(const SceneNode& node, LoadContext& ctx) {
  Rgb radiance = node.get_color("radiance", Rgb(1.f));
  if (!radiance.is_finite() || radiance.r < 0.f || radiance.g < 0.f || radiance.b < 0.f)
    throw SceneError(node.loc, node.describe() + ": radiance must be finite and non-negative");
  return std::make_unique<ConstantLight>(radiance);
}

}  // namespace tessera
