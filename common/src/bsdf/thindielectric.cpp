// Mitsuba 0.6 `thindielectric`: an infinitely thin slab (window pane, bulb glass). Light bouncing
// between the two faces is summed in closed form, and what is transmitted leaves parallel to where
// it came from, so the slab never bends rays and needs no radiance scaling.
#include "tessera/bsdf/dielectric.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/ior.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class ThinDielectricBsdf final : public Bsdf {
 public:
  ThinDielectricBsdf(float eta, std::shared_ptr<const Texture> reflectance, std::shared_ptr<const Texture> transmittance)
      : eta_(eta), reflectance_(std::move(reflectance)), transmittance_(std::move(transmittance)) {
    TESSERA_CHECK(eta > 0.f && reflectance_ && transmittance_);
  }

  Rgb eval(const SurfaceInteraction&, Vec3, Vec3) const override { return {}; }
  float pdf(const SurfaceInteraction&, Vec3, Vec3) const override { return 0.f; }
  bool is_delta() const override { return true; }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2, BsdfSample& out) const override {
    float r = fresnel_dielectric(abs_cos_theta(wo), eta_);
    // Geometric series of the inter-reflections: R + T R T + T R R R T + ... with T = 1 - R.
    if (r < 1.f) {
      const float t = 1.f - r;
      r += t * t * r / (1.f - r * r);
    }
    out.delta = true;
    out.eta = 1.f;
    if (u1 < r) {
      out.wi = Vec3(-wo.x, -wo.y, wo.z);
      out.pdf = r;
      out.weight = reflectance_->eval(si);
    } else {
      out.wi = -wo;
      out.pdf = 1.f - r;
      out.weight = transmittance_->eval(si);
    }
    return true;
  }

 private:
  float eta_;
  std::shared_ptr<const Texture> reflectance_, transmittance_;
};

}  // namespace

std::shared_ptr<Bsdf> make_thindielectric_bsdf(float eta, std::shared_ptr<const Texture> specular_reflectance,
                                               std::shared_ptr<const Texture> specular_transmittance) {
  return std::make_shared<ThinDielectricBsdf>(eta, std::move(specular_reflectance),
                                              std::move(specular_transmittance));
}

std::shared_ptr<Bsdf> make_thindielectric(const SceneNode& node, LoadContext& ctx) {
  const float int_ior = read_ior(node, "int_ior", "bk7");
  const float ext_ior = read_ior(node, "ext_ior", "air");
  if (!(int_ior > 0.f) || !(ext_ior > 0.f))
    throw SceneError(node.loc, node.describe() + ": int_ior and ext_ior must be positive");
  return make_thindielectric_bsdf(int_ior / ext_ior, ctx.texture(node, "specular_reflectance", Rgb(1.f)),
                                  ctx.texture(node, "specular_transmittance", Rgb(1.f)));
}

}  // namespace tessera
