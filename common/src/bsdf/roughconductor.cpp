// Mitsuba 0.6's `roughconductor`: Cook-Torrance microfacet reflection with the exact conductor
// Fresnel term, f(wo, wi) cos_i = F(wo.m) D(m) G(wo, wi, m) / (4 cos_o), m the half vector.
// Roughness may be a texture (evaluated per hit with eval_1); the distribution object is rebuilt at
// each call, which costs a few flops.
#include "tessera/bsdf/conductor.h"
#include "tessera/bsdf/microfacet_params.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/scene/load_context.h"

#include <cmath>

namespace tessera {
namespace {

class RoughConductorBsdf final : public Bsdf {
 public:
  RoughConductorBsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha_u,
                     std::shared_ptr<const Texture> alpha_v, ConductorIor ior,
                     std::shared_ptr<const Texture> specular_reflectance)
      : type_(type), alpha_u_(std::move(alpha_u)), alpha_v_(std::move(alpha_v)), ior_(ior),
        specular_reflectance_(std::move(specular_reflectance)) {
    TESSERA_CHECK(alpha_u_ != nullptr && specular_reflectance_ != nullptr);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return {};
    Vec3 m = normalize(wo + wi);
    MicrofacetDistribution distr = distribution(si);
    float d = distr.D(m);
    if (d == 0.f) return {};
    float g = distr.G(wo, wi, m);
    Rgb f = fresnel_conductor(dot(wo, m), ior_.eta, ior_.k) * specular_reflectance_->eval(si);
    return f * (d * g / (4.f * cos_theta(wo)));
  }

  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return 0.f;
    Vec3 m = normalize(wo + wi);
    float wo_m = dot(wo, m);
    if (wo_m <= 0.f) return 0.f;
    // Jacobian of the reflection about m: d(wi) = 4 (wo.m) d(m).
    return distribution(si).pdf_m(wo, m) / (4.f * wo_m);
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float, Vec2 u2, BsdfSample& out) const override {
    if (cos_theta(wo) <= 0.f) return false;
    MicrofacetDistribution distr = distribution(si);
    MicrofacetSample ms;
    if (!distr.sample_m(wo, u2, ms)) return false;
    float wo_m = dot(wo, ms.m);
    if (wo_m <= 0.f) return false;
    Vec3 wi = 2.f * wo_m * ms.m - wo;
    if (cos_theta(wi) <= 0.f) return false;
    float pdf = ms.pdf / (4.f * wo_m);
    if (!(pdf > 0.f) || !std::isfinite(pdf)) return false;
    float value = distr.D(ms.m) * distr.G(wo, wi, ms.m) / (4.f * cos_theta(wo));
    Rgb f = fresnel_conductor(wo_m, ior_.eta, ior_.k) * specular_reflectance_->eval(si);
    out.wi = wi;
    out.pdf = pdf;
    out.weight = f * (value / pdf);
    out.delta = false;
    return true;
  }

  float roughness(const SurfaceInteraction& si) const override { return distribution(si).roughness(); }

 private:
  MicrofacetDistribution distribution(const SurfaceInteraction& si) const {
    float au = alpha_u_->eval_1(si);
    float av = alpha_v_ ? alpha_v_->eval_1(si) : au;
    return MicrofacetDistribution(type_, au, av);
  }

  MicrofacetType type_;
  std::shared_ptr<const Texture> alpha_u_, alpha_v_;
  ConductorIor ior_;
  std::shared_ptr<const Texture> specular_reflectance_;
};

}  // namespace

std::shared_ptr<Bsdf> make_roughconductor_bsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha_u,
                                               std::shared_ptr<const Texture> alpha_v, ConductorIor ior,
                                               std::shared_ptr<const Texture> specular_reflectance) {
  return std::make_shared<RoughConductorBsdf>(type, std::move(alpha_u), std::move(alpha_v), ior,
                                              std::move(specular_reflectance));
}

std::shared_ptr<Bsdf> make_roughconductor(const SceneNode& node, LoadContext& ctx) {
  const MicrofacetType type = read_microfacet_type(node, ctx);
  const MicrofacetAlpha alpha = read_microfacet_alpha(node, ctx);
  ConductorIor ior = read_conductor_ior(node);
  return make_roughconductor_bsdf(type, alpha.u, alpha.u == alpha.v ? nullptr : alpha.v, ior,
                                  ctx.texture(node, "specular_reflectance", Rgb(1.f)));
}

}  // namespace tessera
