// Mitsuba's `homogeneous` medium: constant extinction sigma_t = sigma_a + sigma_s and albedo.
//
// Distance sampling with chromatic extinction (Mitsuba 0.6's "balance" strategy, pbrt-v3's
// HomogeneousMedium): a channel c is picked uniformly and a distance drawn from
// sigma_t[c] exp(-sigma_t[c] s); the density of the resulting point is the mean over channels, so
// the estimate stays unbiased for every channel however different their extinctions are. A purely
// absorbing medium (sigma_s = 0, staircase2's glass) never samples a scattering point: the segment
// is weighted by its transmittance, which is the zero-variance choice when nothing scatters.
#include "tessera/core/check.h"
#include "tessera/medium/material_presets.h"
#include "tessera/render/medium.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

class HomogeneousMedium final : public Medium {
 public:
  HomogeneousMedium(Rgb sigma_t, Rgb albedo, std::shared_ptr<const PhaseFunction> phase)
      : Medium(std::move(phase)), sigma_t_(sigma_t), sigma_s_(sigma_t * albedo) {
    for (int c = 0; c < 3; ++c) TESSERA_CHECK(sigma_t[c] >= 0.f && albedo[c] >= 0.f && albedo[c] <= 1.f);
    absorbing_only_ = sigma_s_.is_black();
  }

  void sample(const Ray& ray, float tmax, Vec2 u, MediumSample& out) const override {
    const float speed = length(ray.d);
    const float dist_max = tmax < kInfinity ? tmax * speed : kInfinity;
    out.scattered = false;
    out.t = tmax;
    if (!absorbing_only_) {
      const int c = std::min(int(u.x * 3.f), 2);
      if (sigma_t_[c] > 0.f) {
        const float s = -std::log1p(-u.y) / sigma_t_[c];
        if (s < dist_max) {
          Rgb tr = transmittance_over(s);
          float pdf = 0.f;
          for (int k = 0; k < 3; ++k) pdf += sigma_t_[k] * tr[k];
          pdf *= 1.f / 3.f;
          out.scattered = true;
          out.t = s / speed;
          out.weight = pdf > 0.f ? sigma_s_ * tr * (1.f / pdf) : Rgb();
          return;
        }
      }
    }
    Rgb tr = transmittance_over(dist_max);
    if (absorbing_only_) {
      out.weight = tr;
      return;
    }
    // Probability of getting past dist_max: the mean over channels of their transmittances.
    const float p_pass = (tr[0] + tr[1] + tr[2]) * (1.f / 3.f);
    out.weight = p_pass > 0.f ? tr * (1.f / p_pass) : Rgb();
  }

  Rgb transmittance(const Ray& ray, float tmax) const override {
    return transmittance_over(tmax < kInfinity ? tmax * length(ray.d) : kInfinity);
  }

  bool absorbing_only() const override { return absorbing_only_; }

 private:
  // exp(-sigma_t d) per channel; a channel with no extinction transmits everything even over an
  // infinite distance (0 * inf would be NaN).
  Rgb transmittance_over(float dist) const {
    Rgb tr;
    for (int c = 0; c < 3; ++c) tr[c] = sigma_t_[c] > 0.f ? std::exp(-sigma_t_[c] * dist) : 1.f;
    return tr;
  }

  Rgb sigma_t_, sigma_s_;
  bool absorbing_only_ = false;
};

}  // namespace

std::unique_ptr<Medium> make_homogeneous_medium(Rgb sigma_t, Rgb albedo, std::shared_ptr<const PhaseFunction> phase) {
  TESSERA_CHECK(phase != nullptr);
  return std::make_unique<HomogeneousMedium>(sigma_t, albedo, std::move(phase));
}


// The plugin. Mitsuba 0.5/0.6 (see medium/material_presets.h): sigma_s and sigma_a start from the
// `material` preset (Skin1 unless named) times 100, sigmaS/sigmaA or sigmaT/albedo replace them,
// and `scale` (0.5's densityMultiplier) multiplies both. Mitsuba 2/3: sigma_t (1) and albedo (0.75)
// times `scale`.
namespace {

Rgb checked_color(const SceneNode& node, const char* name, Rgb def, bool unit_interval) {
  Rgb c = node.get_color(name, def);
  for (int k = 0; k < 3; ++k)
    if (!(c[k] >= 0.f) || !std::isfinite(c[k]) || (unit_interval && c[k] > 1.f))
      throw SceneError(node.loc_of(name), node.describe() + ": '" + name + "' must be " +
                                              (unit_interval ? "in [0, 1]" : "finite and non-negative"));
  return c;
}

}  // namespace

std::shared_ptr<Medium> make_homogeneous(const SceneNode& node, LoadContext& ctx) {
  const bool by_sigma = node.has("sigma_a") || node.has("sigma_s");
  const bool by_albedo = node.has("sigma_t") || node.has("albedo");
  if (by_sigma && by_albedo)
    throw SceneError(node.loc, node.describe() + ": give sigma_a/sigma_s or sigma_t/albedo, not both");
  const bool legacy = ctx.desc().version_major < 2;
  float scale = node.get_float("scale", legacy ? node.get_float("density_multiplier", 1.f) : 1.f);
  if (!(scale >= 0.f) || !std::isfinite(scale))
    throw SceneError(node.loc_of("scale"), node.describe() + ": 'scale' must be finite and non-negative");

  Rgb sigma_t, albedo;
  if (legacy) {
    const std::string name = node.get_string("material", "Skin1");
    if (node.has("material") && (by_sigma || by_albedo))
      throw SceneError(node.loc_of("material"), node.describe() + ": give a 'material' or coefficients, not both");
    MeasuredMedium preset;
    if (!lookup_measured_medium(name, preset)) {
      std::string known;
      for (const std::string& n : measured_medium_names()) known += (known.empty() ? "" : ", ") + n;
      throw SceneError(node.loc_of("material"), "unknown medium material '" + name + "' (known: " + known + ")");
    }
    auto albedo_of = [](Rgb s, Rgb t) {
      Rgb a;
      for (int c = 0; c < 3; ++c) a[c] = t[c] > 0.f ? s[c] / t[c] : 0.f;
      return a;
    };
    const Rgb preset_s = preset.sigma_s * kMitsuba06PresetFactor, preset_a = preset.sigma_a * kMitsuba06PresetFactor;
    if (by_albedo) {
      sigma_t = checked_color(node, "sigma_t", preset_s + preset_a, false);
      albedo = checked_color(node, "albedo", albedo_of(preset_s, preset_s + preset_a), true);
    } else {
      Rgb sigma_s = checked_color(node, "sigma_s", preset_s, false);
      Rgb sigma_a = checked_color(node, "sigma_a", preset_a, false);
      sigma_t = sigma_s + sigma_a;
      albedo = albedo_of(sigma_s, sigma_t);
    }
  } else {
    if (by_sigma)
      throw SceneError(node.loc, node.describe() + ": Mitsuba 3's homogeneous medium takes sigma_t and albedo");
    sigma_t = checked_color(node, "sigma_t", Rgb(1.f), false);
    albedo = checked_color(node, "albedo", Rgb(0.75f), true);
  }
  return make_homogeneous_medium(sigma_t * scale, albedo, ctx.phase(node));
}

}  // namespace tessera
