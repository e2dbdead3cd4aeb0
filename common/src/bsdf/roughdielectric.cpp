// Mitsuba 0.6's `roughdielectric` (Walter et al. 2007, "Microfacet Models for Refraction through
// Rough Surfaces"). Naming maps Mitsuba's bRec.wi to our `wo` (the direction towards the camera)
// and bRec.wo to our `wi` (the sampled one).
//
// Half vector: wo + wi for reflection, wo + eta' wi for refraction (eta' the IOR on wi's side over
// wo's side), flipped onto the +z hemisphere. Unlike Mitsuba 0.6, the microfacet configuration is
// also required to be consistent on both sides (dot(w, m) of the same sign as cos(w), as Mitsuba 3
// does): otherwise sample() could draw back-facing micro-normals whose G is 0 and pdf() would report
// density where sample() never goes. Mitsuba 0.6's widened sampling roughness
// (alpha * (1.2 - 0.2 sqrt|cos|)) is not used: sampling uses the distribution of eval().
#include "tessera/bsdf/roughdielectric.h"
#include "tessera/bsdf/microfacet_params.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/ior.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/scene/load_context.h"

#include <cmath>

namespace tessera {
namespace {

float sign_of(float x) { return x < 0.f ? -1.f : 1.f; }

class RoughDielectricBsdf final : public Bsdf {
 public:
  RoughDielectricBsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha_u,
                      std::shared_ptr<const Texture> alpha_v, float eta,
                      std::shared_ptr<const Texture> reflectance, std::shared_ptr<const Texture> transmittance)
      : type_(type), alpha_u_(std::move(alpha_u)), alpha_v_(std::move(alpha_v)), eta_(eta), inv_eta_(1.f / eta),
        reflectance_(std::move(reflectance)), transmittance_(std::move(transmittance)) {
    TESSERA_CHECK(eta > 0.f && alpha_u_ && reflectance_ && transmittance_);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    const float cos_o = cos_theta(wo), cos_i = cos_theta(wi);
    if (cos_o == 0.f || cos_i == 0.f) return {};
    const bool reflect = cos_o * cos_i > 0.f;
    const float eta = cos_o > 0.f ? eta_ : inv_eta_;  // IOR on wi's side over wo's side, if refracted
    Vec3 m;
    if (!half_vector(wo, wi, reflect, eta, m)) return {};
    const MicrofacetDistribution distr = distribution(si);
    const float d = distr.D(m);
    if (d == 0.f) return {};
    const float wo_m = dot(wo, m), wi_m = dot(wi, m);
    const float f = fresnel_dielectric(wo_m, eta_);
    const float g = distr.G(wo, wi, m);
    if (reflect) return reflectance_->eval(si) * (f * d * g / (4.f * std::abs(cos_o)));
    const float denom = wo_m + eta * wi_m;
    // (1 - F) D G eta'^2 |wo.m wi.m| / (|cos_o| denom^2), then the radiance scaling 1/eta'^2: the
    // two eta'^2 cancel.
    const float value = (1.f - f) * d * g * std::abs(wo_m * wi_m) / (std::abs(cos_o) * denom * denom);
    return transmittance_->eval(si) * value;
  }

  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    const float cos_o = cos_theta(wo), cos_i = cos_theta(wi);
    if (cos_o == 0.f || cos_i == 0.f) return 0.f;
    const bool reflect = cos_o * cos_i > 0.f;
    const float eta = cos_o > 0.f ? eta_ : inv_eta_;
    Vec3 m;
    if (!half_vector(wo, wi, reflect, eta, m)) return 0.f;
    const float wo_m = dot(wo, m), wi_m = dot(wi, m);
    float dm_dwi;  // Jacobian of the map from micro-normal to wi
    if (reflect) {
      dm_dwi = 1.f / (4.f * std::abs(wi_m));
    } else {
      const float denom = wo_m + eta * wi_m;
      dm_dwi = eta * eta * std::abs(wi_m) / (denom * denom);
    }
    const float f = fresnel_dielectric(wo_m, eta_);
    const float pdf_m = distribution(si).pdf_m(sign_of(cos_o) * wo, m);
    return pdf_m * (reflect ? f : 1.f - f) * dm_dwi;
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    const float cos_o = cos_theta(wo);
    if (cos_o == 0.f) return false;
    const MicrofacetDistribution distr = distribution(si);
    MicrofacetSample ms;
    if (!distr.sample_m(sign_of(cos_o) * wo, u2, ms) || !(ms.pdf > 0.f)) return false;
    const Vec3 m = ms.m;
    const float wo_m = dot(wo, m);
    if (wo_m * cos_o <= 0.f) return false;  // back-facing micro-normal
    float cos_t = 0.f;
    const float f = fresnel_dielectric(wo_m, eta_, &cos_t);
    Vec3 wi;
    float lobe_pdf, dm_dwi;
    Rgb weight;
    if (u1 < f) {
      wi = 2.f * wo_m * m - wo;
      if (cos_theta(wi) * cos_o <= 0.f) return false;
      lobe_pdf = f;
      dm_dwi = 1.f / (4.f * std::abs(wo_m));
      weight = reflectance_->eval(si);
      out.eta = 1.f;
    } else {
      if (cos_t == 0.f) return false;  // total internal reflection has F = 1: not reached
      const bool entering = cos_t < 0.f;
      const float s = entering ? inv_eta_ : eta_;  // n on wo's side over n on wi's side
      wi = (wo_m * s + cos_t) * m - s * wo;
      const float wi_len2 = dot(wi, wi);
      if (!(wi_len2 > 0.f)) return false;
      wi = wi / std::sqrt(wi_len2);
      if (cos_theta(wi) * cos_o >= 0.f) return false;
      const float eta = 1.f / s;
      const float wi_m = dot(wi, m);
      const float denom = wo_m + eta * wi_m;
      lobe_pdf = 1.f - f;
      dm_dwi = eta * eta * std::abs(wi_m) / (denom * denom);
      // Radiance scaling (n_wo / n_wi)^2, as the smooth dielectric.
      weight = transmittance_->eval(si) * (s * s);
      out.eta = entering ? eta_ : inv_eta_;
    }
    const float pdf = ms.pdf * lobe_pdf * dm_dwi;
    if (!(pdf > 0.f) || !std::isfinite(pdf)) return false;
    // eval / pdf simplifies to D G |wo.m| / (pdf_m |cos_o|) for both lobes (F and Jacobians cancel).
    const float g = distr.G(wo, wi, m);
    const float ratio = distr.D(m) * g * std::abs(wo_m) / (ms.pdf * std::abs(cos_o));
    out.wi = wi;
    out.pdf = pdf;
    out.weight = weight * ratio;
    out.delta = false;
    return true;
  }

  float roughness(const SurfaceInteraction& si) const override { return distribution(si).roughness(); }

 private:
  /// Generalised half vector on +z; false for a degenerate or side-inconsistent configuration.
  static bool half_vector(Vec3 wo, Vec3 wi, bool reflect, float eta, Vec3& m) {
    Vec3 h = reflect ? wo + wi : wo + eta * wi;
    const float len2 = dot(h, h);
    if (!(len2 > 0.f)) return false;
    h = h / std::sqrt(len2);
    if (h.z < 0.f) h = -h;
    if (!(h.z > 0.f)) return false;
    if (dot(wo, h) * cos_theta(wo) <= 0.f || dot(wi, h) * cos_theta(wi) <= 0.f) return false;
    m = h;
    return true;
  }

  MicrofacetDistribution distribution(const SurfaceInteraction& si) const {
    const float au = alpha_u_->eval_1(si);
    const float av = alpha_v_ ? alpha_v_->eval_1(si) : au;
    return MicrofacetDistribution(type_, au, av);
  }

  MicrofacetType type_;
  std::shared_ptr<const Texture> alpha_u_, alpha_v_;
  float eta_, inv_eta_;
  std::shared_ptr<const Texture> reflectance_, transmittance_;
};

}  // namespace

std::shared_ptr<Bsdf> make_roughdielectric_bsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha_u,
                                                std::shared_ptr<const Texture> alpha_v, float eta,
                                                std::shared_ptr<const Texture> specular_reflectance,
                                                std::shared_ptr<const Texture> specular_transmittance) {
  return std::make_shared<RoughDielectricBsdf>(type, std::move(alpha_u), std::move(alpha_v), eta,
                                               std::move(specular_reflectance), std::move(specular_transmittance));
}

std::shared_ptr<Bsdf> make_roughdielectric(const SceneNode& node, LoadContext& ctx) {
  const MicrofacetType type = read_microfacet_type(node, ctx);
  const MicrofacetAlpha alpha = read_microfacet_alpha(node, ctx);
  const float int_ior = read_ior(node, "int_ior", "bk7");
  const float ext_ior = read_ior(node, "ext_ior", "air");
  if (!(int_ior > 0.f) || !(ext_ior > 0.f))
    throw SceneError(node.loc, node.describe() + ": int_ior and ext_ior must be positive");
  return make_roughdielectric_bsdf(type, alpha.u, alpha.u == alpha.v ? nullptr : alpha.v, int_ior / ext_ior,
                                   ctx.texture(node, "specular_reflectance", Rgb(1.f)),
                                   ctx.texture(node, "specular_transmittance", Rgb(1.f)));
}

}  // namespace tessera
