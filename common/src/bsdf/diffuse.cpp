#include "tessera/bsdf/diffuse.h"

#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class DiffuseBsdf final : public Bsdf {
 public:
  explicit DiffuseBsdf(std::shared_ptr<const Texture> reflectance) : reflectance_(std::move(reflectance)) {
    TESSERA_CHECK(reflectance_ != nullptr);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return {};
    return reflectance_->eval(si) * (cos_theta(wi) * kInvPi);
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
    out.weight = reflectance_->eval(si);  // eval * cos / pdf: the cosine and 1/pi cancel
    out.delta = false;
    return true;
  }

 private:
  std::shared_ptr<const Texture> reflectance_;
};

}  // namespace

std::shared_ptr<Bsdf> make_diffuse_bsdf(std::shared_ptr<const Texture> reflectance) {
  return std::make_shared<DiffuseBsdf>(std::move(reflectance));
}

std::shared_ptr<Bsdf> make_diffuse(const SceneNode& node, LoadContext& ctx) {
  return make_diffuse_bsdf(ctx.texture(node, "reflectance", Rgb(0.5f)));
}

}  // namespace tessera
