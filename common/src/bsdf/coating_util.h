// Pieces shared by `coating` and `roughcoating` (Mitsuba 0.6 coating.cpp / roughcoating.cpp).
#pragma once

#include "tessera/bsdf/fresnel.h"
#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/render/texture.h"
#include "tessera/scene/load_context.h"

#include <cmath>
#include <memory>

namespace tessera::coating {

/// Refraction of `w` through a smooth interface into a medium of relative IOR `eta` (n_to / n_from),
/// staying in w's hemisphere (the layer is thin: only the direction's tilt matters). Sets the
/// Fresnel reflectance `f`; false under total internal reflection.
inline bool refract(Vec3 w, float eta, Vec3& out, float& f) {
  float cos_t = 0.f;
  f = fresnel_dielectric(std::abs(w.z), eta, &cos_t);
  if (f >= 1.f) return false;
  out = Vec3(w.x / eta, w.y / eta, std::copysign(std::abs(cos_t), w.z));
  return true;
}

/// Mitsuba's steering of samples between the interface and the nested BSDF: with a clear layer
/// 0.5, less when absorption makes the nested part darker.
inline float specular_sampling_weight(const Texture& sigma_a, float thickness) {
  const Rgb s = sigma_a.mean();
  const Rgb t(std::exp(-2.f * thickness * s.r), std::exp(-2.f * thickness * s.g), std::exp(-2.f * thickness * s.b));
  return 1.f / (t.average() + 1.f);
}

/// Probability of sampling the interface given its reflectance r, reallocated by `weight`.
inline float prob_specular(float r, float weight) {
  const float a = r * weight, b = (1.f - r) * (1.f - weight);
  return a + b > 0.f ? a / (a + b) : 0.f;
}

/// exp(-sigma_a thickness (1/|cos_i'| + 1/|cos_o'|)) along the refracted directions.
inline Rgb absorption(Rgb sigma_a, float thickness, Vec3 wo_in, Vec3 wi_in) {
  if (sigma_a.is_black() || thickness == 0.f) return Rgb(1.f);
  const float len = thickness * (1.f / std::abs(wo_in.z) + 1.f / std::abs(wi_in.z));
  // A clear channel stays 1 even at grazing angles, where len is huge (0 * inf would be NaN).
  auto channel = [len](float s) { return s > 0.f ? std::exp(-s * len) : 1.f; };
  return Rgb(channel(sigma_a.r), channel(sigma_a.g), channel(sigma_a.b));
}

/// `specular_reflectance` (default 1) with Mitsuba's ensureEnergyConservation (default on): a
/// reflectance above 1 is scaled by 0.99 / max, judged on the texture's mean (what our textures offer).
std::shared_ptr<const Texture> read_specular_reflectance(const SceneNode& node, LoadContext& ctx);

/// `int_ior` (default bk7) / `ext_ior` (default air); SceneError unless both positive and different
/// (Mitsuba's check).
float read_coating_eta(const SceneNode& node);

}  // namespace tessera::coating
