// Mitsuba 0.6 smooth `plastic`: a dielectric coat (delta Fresnel reflection) over a Lambertian base.
// Light refracted into the coat scatters diffusely and is reflected back by the coat's underside
// with the hemispherical average fdr_int; summing that series gives the diffuse term
//   rho / (1 - fdr_int)            (default, keeps texture colours), or
//   rho / (1 - rho * fdr_int)      (`nonlinear`: the exact series, saturating colours),
// times (1 - F(wo)) (1 - F(wi)) / eta^2 for entering and leaving the coat.
#include "tessera/bsdf/dielectric.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/ior.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/scene/load_context.h"

#include <cmath>

namespace tessera {

float fresnel_diffuse_reflectance(float eta) {
  // 2 * int_0^1 F(c) c dc = int_0^1 F(sqrt(x)) dx; midpoint rule in x (the kink at the critical
  // angle costs O(1/n^2) with n this large, well below Mitsuba's 1e-5 quadrature tolerance).
  constexpr int kSteps = 1 << 16;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) sum += fresnel_dielectric(std::sqrt((i + 0.5f) / kSteps), eta);
  return float(sum / kSteps);
}

namespace {

class PlasticBsdf final : public Bsdf {
 public:
  PlasticBsdf(float eta, std::shared_ptr<const Texture> diffuse, std::shared_ptr<const Texture> specular,
              bool nonlinear)
      : eta_(eta), inv_eta2_(1.f / (eta * eta)), fdr_int_(fresnel_diffuse_reflectance(1.f / eta)),
        nonlinear_(nonlinear), diffuse_(std::move(diffuse)), specular_(std::move(specular)) {
    TESSERA_CHECK(eta > 0.f && diffuse_ && specular_);
    const float d = diffuse_->mean().luminance(), s = specular_->mean().luminance();
    specular_weight_ = d + s > 0.f ? s / (d + s) : 0.5f;
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return {};
    const float f_o = fresnel_dielectric(cos_theta(wo), eta_), f_i = fresnel_dielectric(cos_theta(wi), eta_);
    return diffuse_term(si) * (kInvPi * cos_theta(wi) * inv_eta2_ * (1.f - f_o) * (1.f - f_i));
  }

  float pdf(const SurfaceInteraction&, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return 0.f;
    return (1.f - prob_specular(fresnel_dielectric(cos_theta(wo), eta_))) * cosine_hemisphere_pdf(cos_theta(wi));
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    if (cos_theta(wo) <= 0.f) return false;
    const float f_o = fresnel_dielectric(cos_theta(wo), eta_);
    const float p_spec = prob_specular(f_o);
    out.eta = 1.f;
    if (u1 < p_spec) {
      out.wi = Vec3(-wo.x, -wo.y, wo.z);
      out.pdf = p_spec;
      out.weight = specular_->eval(si) * (f_o / p_spec);
      out.delta = true;
      return true;
    }
    const Vec3 wi = square_to_cosine_hemisphere(u2);
    const float pdf = (1.f - p_spec) * cosine_hemisphere_pdf(cos_theta(wi));
    if (!(pdf > 0.f)) return false;
    const float f_i = fresnel_dielectric(cos_theta(wi), eta_);
    out.wi = wi;
    out.pdf = pdf;
    out.weight = diffuse_term(si) * (inv_eta2_ * (1.f - f_o) * (1.f - f_i) / (1.f - p_spec));
    out.delta = false;
    return true;
  }

 private:
  // Fresnel-weighted lobe choice, steered by the textures' mean luminances (as Mitsuba).
  float prob_specular(float f) const {
    const float a = f * specular_weight_, b = (1.f - f) * (1.f - specular_weight_);
    return a + b > 0.f ? a / (a + b) : 0.f;
  }

  Rgb diffuse_term(const SurfaceInteraction& si) const {
    const Rgb rho = diffuse_->eval(si);
    if (nonlinear_) return rho / (Rgb(1.f) - rho * fdr_int_);
    return rho * (1.f / (1.f - fdr_int_));
  }

  float eta_, inv_eta2_, fdr_int_;
  bool nonlinear_;
  float specular_weight_ = 0.5f;
  std::shared_ptr<const Texture> diffuse_, specular_;
};

}  // namespace

std::shared_ptr<Bsdf> make_plastic_bsdf(float eta, std::shared_ptr<const Texture> diffuse_reflectance,
                                        std::shared_ptr<const Texture> specular_reflectance, bool nonlinear) {
  return std::make_shared<PlasticBsdf>(eta, std::move(diffuse_reflectance), std::move(specular_reflectance),
                                       nonlinear);
}

std::shared_ptr<Bsdf> make_plastic(const SceneNode& node, LoadContext& ctx) {
  const float int_ior = read_ior(node, "int_ior", "polypropylene");
  const float ext_ior = read_ior(node, "ext_ior", "air");
  if (!(int_ior > 0.f) || !(ext_ior > 0.f))
    throw SceneError(node.loc, node.describe() + ": int_ior and ext_ior must be positive");
  return make_plastic_bsdf(int_ior / ext_ior, ctx.texture(node, "diffuse_reflectance", Rgb(0.5f)),
                           ctx.texture(node, "specular_reflectance", Rgb(1.f)), node.get_bool("nonlinear", false));
}

}  // namespace tessera
