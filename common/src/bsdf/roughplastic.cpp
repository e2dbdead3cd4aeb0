// Mitsuba 0.6's `roughplastic`: microfacet reflection off a rough dielectric coat,
//   f_s cos_i = F(wo.m) D(m) G(wo, wi, m) / (4 cos_o) * specular_reflectance,
// plus a Lambertian base seen through the coat,
//   f_d cos_i = rho' T_ext(cos_o) T_ext(cos_i) / eta^2 * cos_i / pi,
// with rho' = rho / (1 - Fdr) (default) or rho / (1 - rho Fdr) (`nonlinear`), as in the smooth plastic.
//
// Mitsuba reads T_ext(cos, alpha, eta) and the internal diffuse reflectance Fdr from precomputed
// tables (data/microfacet/*.dat) that are not available here. Instead, for the BSDF's fixed alpha
// and eta, the constructor tabulates the same quantity -- the directional albedo of the rough
// dielectric interface's transmission lobe (Walter et al. 2007, with this distribution and Smith G)
// -- over kTableSize cos_theta values, linearly interpolated:
//  - T_ext(c) with eta (light entering the coat), used for both coat crossings; 1 - T_ext(cos_o)
//    also drives the lobe choice as in Mitsuba;
//  - T_int(c) with 1/eta (light leaving from inside, total internal reflection included), whose
//    cosine-weighted hemispherical average gives Fdr = 1 - 2 int_0^1 T_int(c) c dc.
// Each entry is a deterministic stratified estimate (64 x 64) over the distribution's own
// micro-normal sampler. The tables need a fixed alpha, so textured alpha is not supported: the
// factory reports it and uses the texture's mean.
#include "tessera/bsdf/roughplastic.h"

#include "tessera/bsdf/rough_transmittance.h"

#include "tessera/bsdf/microfacet_params.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/ior.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>

namespace tessera {

namespace {

class RoughPlasticBsdf final : public Bsdf {
 public:
  RoughPlasticBsdf(MicrofacetType type, float alpha, float eta, std::shared_ptr<const Texture> diffuse,
                   std::shared_ptr<const Texture> specular, bool nonlinear)
      : distr_(type, alpha), eta_(eta), inv_eta2_(1.f / (eta * eta)), t_ext_(type, alpha, eta),
        nonlinear_(nonlinear), diffuse_(std::move(diffuse)), specular_(std::move(specular)) {
    TESSERA_CHECK(eta > 0.f && diffuse_ && specular_);
    fdr_int_ = 1.f - TransmittanceTable(type, alpha, 1.f / eta).cosine_average();
    const float d = diffuse_->mean().luminance(), s = specular_->mean().luminance();
    specular_weight_ = d + s > 0.f ? s / (d + s) : 0.5f;
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return {};
    Rgb result;
    const Vec3 m = normalize(wo + wi);
    const float d = distr_.D(m);
    if (d > 0.f) {
      const float value = fresnel_dielectric(dot(wo, m), eta_) * d * distr_.G(wo, wi, m) / (4.f * cos_theta(wo));
      result = specular_->eval(si) * value;
    }
    const float t = t_ext_.eval(cos_theta(wo)) * t_ext_.eval(cos_theta(wi));
    return result + diffuse_term(si) * (kInvPi * cos_theta(wi) * inv_eta2_ * t);
  }

  float pdf(const SurfaceInteraction&, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return 0.f;
    return mixed_pdf(wo, wi, prob_specular(cos_theta(wo)));
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    if (cos_theta(wo) <= 0.f) return false;
    const float p_spec = prob_specular(cos_theta(wo));
    Vec3 wi;
    if (u1 < p_spec) {
      MicrofacetSample ms;
      if (!distr_.sample_m(wo, u2, ms)) return false;
      const float wo_m = dot(wo, ms.m);
      if (wo_m <= 0.f) return false;
      wi = 2.f * wo_m * ms.m - wo;
    } else {
      wi = square_to_cosine_hemisphere(u2);
    }
    if (cos_theta(wi) <= 0.f) return false;
    // Both lobes can produce any direction: the weight is the full eval over the mixed pdf (MIS-safe).
    const float pdf = mixed_pdf(wo, wi, p_spec);
    if (!(pdf > 0.f) || !std::isfinite(pdf)) return false;
    out.wi = wi;
    out.pdf = pdf;
    out.weight = eval(si, wo, wi) / pdf;
    out.delta = false;
    out.eta = 1.f;
    return true;
  }

 private:
  float mixed_pdf(Vec3 wo, Vec3 wi, float p_spec) const {
    const Vec3 m = normalize(wo + wi);
    const float wo_m = dot(wo, m);
    const float spec = wo_m > 0.f ? distr_.pdf_m(wo, m) / (4.f * wo_m) : 0.f;
    return p_spec * spec + (1.f - p_spec) * cosine_hemisphere_pdf(cos_theta(wi));
  }

  // Mitsuba: the coat's reflectance 1 - T_ext(cos_o), steered by the textures' mean luminances.
  float prob_specular(float cos_o) const {
    const float r = 1.f - t_ext_.eval(cos_o);
    const float a = r * specular_weight_, b = (1.f - r) * (1.f - specular_weight_);
    return a + b > 0.f ? a / (a + b) : 0.f;
  }

  Rgb diffuse_term(const SurfaceInteraction& si) const {
    const Rgb rho = diffuse_->eval(si);
    if (nonlinear_) return rho / (Rgb(1.f) - rho * fdr_int_);
    return rho * (1.f / (1.f - fdr_int_));
  }

  MicrofacetDistribution distr_;
  float eta_, inv_eta2_;
  TransmittanceTable t_ext_;
  float fdr_int_ = 0.f;
  bool nonlinear_;
  float specular_weight_ = 0.5f;
  std::shared_ptr<const Texture> diffuse_, specular_;
};

}  // namespace

std::shared_ptr<Bsdf> make_roughplastic_bsdf(MicrofacetType type, float alpha, float eta,
                                             std::shared_ptr<const Texture> diffuse_reflectance,
                                             std::shared_ptr<const Texture> specular_reflectance, bool nonlinear) {
  return std::make_shared<RoughPlasticBsdf>(type, alpha, eta, std::move(diffuse_reflectance),
                                            std::move(specular_reflectance), nonlinear);
}

std::shared_ptr<Bsdf> make_roughplastic(const SceneNode& node, LoadContext& ctx) {
  const MicrofacetType type = read_microfacet_type(node, ctx);
  const std::shared_ptr<Texture> alpha_tex = ctx.texture(node, "alpha", Rgb(0.1f));
  if (dynamic_cast<const ConstantTexture*>(alpha_tex.get()) == nullptr) {
    const Property* p = node.find("alpha");
    ctx.unsupported(p ? p->loc : node.loc, node.describe() + " textured alpha", "the texture's mean");
  }
  const float alpha = alpha_tex->mean().average();
  if (!(alpha > 0.f)) throw SceneError(node.loc, node.describe() + ": alpha must be positive");
  const float int_ior = read_ior(node, "int_ior", "polypropylene");
  const float ext_ior = read_ior(node, "ext_ior", "air");
  if (!(int_ior > 0.f) || !(ext_ior > 0.f))
    throw SceneError(node.loc, node.describe() + ": int_ior and ext_ior must be positive");
  return make_roughplastic_bsdf(type, alpha, int_ior / ext_ior,
                                ctx.texture(node, "diffuse_reflectance", Rgb(0.5f)),
                                ctx.texture(node, "specular_reflectance", Rgb(1.f)),
                                node.get_bool("nonlinear", false));
}

}  // namespace tessera
