// Mitsuba 0.6 `dielectric`: a smooth interface between two dielectrics. Both lobes are deltas; the
// lobe is picked with the Fresnel reflectance F, so a sample's weight is the lobe's texture (times
// the radiance scaling for refraction), never F itself.
#include "tessera/bsdf/dielectric.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/ior.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class DielectricBsdf final : public Bsdf {
 public:
  DielectricBsdf(float eta, std::shared_ptr<const Texture> reflectance, std::shared_ptr<const Texture> transmittance)
      : eta_(eta), inv_eta_(1.f / eta), reflectance_(std::move(reflectance)), transmittance_(std::move(transmittance)) {
    TESSERA_CHECK(eta > 0.f && reflectance_ && transmittance_);
  }

  Rgb eval(const SurfaceInteraction&, Vec3, Vec3) const override { return {}; }
  float pdf(const SurfaceInteraction&, Vec3, Vec3) const override { return 0.f; }
  bool is_delta() const override { return true; }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2, BsdfSample& out) const override {
    float cos_t = 0.f;
    const float f = fresnel_dielectric(cos_theta(wo), eta_, &cos_t);
    out.delta = true;
    if (u1 < f) {
      out.wi = Vec3(-wo.x, -wo.y, wo.z);
      out.pdf = f;
      out.weight = reflectance_->eval(si);
      out.eta = 1.f;
      return true;
    }
    // cos_t < 0: wo is outside and the ray enters the interior (tangential part shrinks by 1/eta).
    const bool entering = cos_t < 0.f;
    const float scale = entering ? inv_eta_ : eta_;
    out.wi = Vec3(-scale * wo.x, -scale * wo.y, cos_t);
    out.pdf = 1.f - f;
    // Radiance is not invariant across the interface: L_wo = L_wi * (n_wo / n_wi)^2, which is
    // (1/eta)^2 entering and eta^2 leaving. Camera paths carry radiance, so the weight has it.
    out.weight = transmittance_->eval(si) * (scale * scale);
    out.eta = entering ? eta_ : inv_eta_;
    return true;
  }

 private:
  float eta_, inv_eta_;
  std::shared_ptr<const Texture> reflectance_, transmittance_;
};

}  // namespace

std::shared_ptr<Bsdf> make_dielectric_bsdf(float eta, std::shared_ptr<const Texture> specular_reflectance,
                                           std::shared_ptr<const Texture> specular_transmittance) {
  return std::make_shared<DielectricBsdf>(eta, std::move(specular_reflectance), std::move(specular_transmittance));
}

std::shared_ptr<Bsdf> make_dielectric(const SceneNode& node, LoadContext& ctx) {
  const float int_ior = read_ior(node, "int_ior", "bk7");
  const float ext_ior = read_ior(node, "ext_ior", "air");
  if (!(int_ior > 0.f) || !(ext_ior > 0.f))
    throw SceneError(node.loc, node.describe() + ": int_ior and ext_ior must be positive");
  return make_dielectric_bsdf(int_ior / ext_ior, ctx.texture(node, "specular_reflectance", Rgb(1.f)),
                              ctx.texture(node, "specular_transmittance", Rgb(1.f)));
}

}  // namespace tessera
