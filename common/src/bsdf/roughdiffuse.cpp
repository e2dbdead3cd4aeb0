// Oren–Nayar rough diffuse reflection with Mitsuba 0.6's `roughdiffuse` semantics: Beckmann-style
// `alpha` converted to the Oren–Nayar slope deviation by 1/sqrt(2) (Mitsuba's fit), either the
// qualitative "fast" model or the full model of Oren and Nayar (1994) including the
// two-bounce interreflection term. The BRDF is symmetric, so the roles of wo/wi in Mitsuba's
// code carry over unchanged; only the cosine is that of the light direction `wi`.
#include "tessera/bsdf/roughdiffuse.h"

#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tessera {
namespace {

float safe_sqrt(float x) { return std::sqrt(std::max(0.f, x)); }
float safe_acos(float x) { return std::acos(std::clamp(x, -1.f, 1.f)); }

class RoughDiffuseBsdf final : public Bsdf {
 public:
  RoughDiffuseBsdf(std::shared_ptr<const Texture> reflectance, std::shared_ptr<const Texture> alpha,
                   bool fast_approx)
      : reflectance_(std::move(reflectance)), alpha_(std::move(alpha)), fast_approx_(fast_approx) {
    TESSERA_CHECK(reflectance_ != nullptr && alpha_ != nullptr);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return {};
    // Beckmann RMS roughness -> Oren–Nayar slope-area deviation (Mitsuba's 1/sqrt(2) fit).
    const float sigma = alpha_->eval_1(si) * 0.70710678f;
    const float sigma2 = sigma * sigma;
    const float sin_o = safe_sqrt(1.f - wo.z * wo.z), sin_i = safe_sqrt(1.f - wi.z * wi.z);

    float cos_phi_diff = 0.f;
    if (sin_o > 1e-4f && sin_i > 1e-4f)
      cos_phi_diff = std::clamp((wo.x * wi.x + wo.y * wi.y) / (sin_o * sin_i), -1.f, 1.f);

    // alpha = max(theta_o, theta_i), beta = min: the direction nearer the normal gives beta.
    float sin_alpha, sin_beta, tan_beta;
    if (wo.z > wi.z) {
      sin_alpha = sin_i;
      sin_beta = sin_o;
      tan_beta = sin_o / wo.z;
    } else {
      sin_alpha = sin_o;
      sin_beta = sin_i;
      tan_beta = sin_i / wi.z;
    }

    const Rgb rho = reflectance_->eval(si);
    if (fast_approx_) {
      const float a = 1.f - 0.5f * sigma2 / (sigma2 + 0.33f);
      const float b = 0.45f * sigma2 / (sigma2 + 0.09f);
      return rho * (kInvPi * wi.z * (a + b * std::max(cos_phi_diff, 0.f) * sin_alpha * tan_beta));
    }

    const float theta_o = safe_acos(wo.z), theta_i = safe_acos(wi.z);
    const float alpha = std::max(theta_o, theta_i), beta = std::min(theta_o, theta_i);
    const float tmp = sigma2 / (sigma2 + 0.09f);
    const float tmp2 = (4.f * kInvPi * kInvPi) * alpha * beta;
    const float tmp3 = 2.f * beta * kInvPi;
    const float c1 = 1.f - 0.5f * sigma2 / (sigma2 + 0.33f);
    float c2 = 0.45f * tmp;
    const float c3 = 0.125f * tmp * tmp2 * tmp2;
    const float c4 = 0.17f * sigma2 / (sigma2 + 0.13f);
    c2 *= cos_phi_diff > 0.f ? sin_alpha : sin_alpha - tmp3 * tmp3 * tmp3;
    // tan((alpha + beta) / 2) by the half-angle formula, without trigonometric calls.
    const float tan_half = (sin_alpha + sin_beta) / (safe_sqrt(1.f - sin_alpha * sin_alpha) +
                                                     safe_sqrt(1.f - sin_beta * sin_beta));
    const Rgb single = rho * (c1 + cos_phi_diff * c2 * tan_beta + (1.f - std::abs(cos_phi_diff)) * c3 * tan_half);
    const Rgb interreflection = rho * rho * (c4 * (1.f - cos_phi_diff * tmp3 * tmp3));
    return (single + interreflection) * (kInvPi * wi.z);
  }

  float pdf(const SurfaceInteraction&, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return 0.f;
    return cosine_hemisphere_pdf(cos_theta(wi));
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float, Vec2 u2, BsdfSample& out) const override {
    if (cos_theta(wo) <= 0.f) return false;
    Vec3 wi = square_to_cosine_hemisphere(u2);
    float pdf = cosine_hemisphere_pdf(cos_theta(wi));
    if (!(pdf > 0.f)) return false;
    out.wi = wi;
    out.pdf = pdf;
    out.weight = eval(si, wo, wi) / pdf;
    out.delta = false;
    out.eta = 1.f;
    return true;
  }

 private:
  std::shared_ptr<const Texture> reflectance_;
  std::shared_ptr<const Texture> alpha_;
  bool fast_approx_;
};

}  // namespace

std::shared_ptr<Bsdf> make_roughdiffuse_bsdf(std::shared_ptr<const Texture> reflectance,
                                             std::shared_ptr<const Texture> alpha, bool fast_approx) {
  return std::make_shared<RoughDiffuseBsdf>(std::move(reflectance), std::move(alpha), fast_approx);
}

std::shared_ptr<Bsdf> make_roughdiffuse(const SceneNode& node, LoadContext& ctx) {
  // Mitsuba accepts `diffuseReflectance` as a synonym for compatibility with other models.
  auto given = [&](const char* name) { return node.find(name) != nullptr || node.named_child(name) != nullptr; };
  const char* refl_name = !given("reflectance") && given("diffuse_reflectance") ? "diffuse_reflectance" : "reflectance";
  std::shared_ptr<const Texture> reflectance = ctx.texture(node, refl_name, Rgb(0.5f));
  // Mitsuba's ensureEnergyConservation: a reflectance above 1 is scaled by 0.99 / max. Mitsuba uses
  // the texture's maximum; the Texture interface offers the mean (the maximum for a constant).
  const Rgb m = reflectance->mean();
  const float max_refl = std::max({m.r, m.g, m.b});
  if (node.get_bool("ensure_energy_conservation", true) && max_refl > 1.f) {
    const float scale = 0.99f / max_refl;
    std::ostringstream msg;
    msg << "roughdiffuse: reflectance reaches " << max_refl << " (> 1, not energy conserving); scaled by "
        << scale << " as Mitsuba does (ensureEnergyConservation=false prevents this)";
    ctx.warn(node.loc, msg.str());
    reflectance = make_scaled_texture(std::move(reflectance), scale);
  }
  auto alpha = ctx.texture(node, "alpha", Rgb(0.2f));
  return make_roughdiffuse_bsdf(std::move(reflectance), std::move(alpha), node.get_bool("use_fast_approx", false));
}

}  // namespace tessera
