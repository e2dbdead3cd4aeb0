// Mitsuba 0.6's smooth `conductor`: a perfect mirror weighted by the exact conductor Fresnel term.
#include "tessera/bsdf/conductor.h"

#include "tessera/bsdf/fresnel.h"
#include "tessera/bsdf/ior.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

class ConductorBsdf final : public Bsdf {
 public:
  ConductorBsdf(ConductorIor ior, std::shared_ptr<const Texture> specular_reflectance)
      : ior_(ior), specular_reflectance_(std::move(specular_reflectance)) {
    TESSERA_CHECK(specular_reflectance_ != nullptr);
  }

  // The only lobe is a delta: nothing to evaluate for a given pair of directions.
  Rgb eval(const SurfaceInteraction&, Vec3, Vec3) const override { return {}; }
  float pdf(const SurfaceInteraction&, Vec3, Vec3) const override { return 0.f; }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float, Vec2, BsdfSample& out) const override {
    if (cos_theta(wo) <= 0.f) return false;
    out.wi = Vec3(-wo.x, -wo.y, wo.z);
    out.pdf = 1.f;
    out.weight = fresnel_conductor(cos_theta(wo), ior_.eta, ior_.k) * specular_reflectance_->eval(si);
    out.delta = true;
    return true;
  }

  bool is_delta() const override { return true; }

 private:
  ConductorIor ior_;
  std::shared_ptr<const Texture> specular_reflectance_;
};

}  // namespace

ConductorIor read_conductor_ior(const SceneNode& node) {
  std::string material = node.get_string("material", "Cu");
  std::optional<ConductorIor> named = lookup_metal(material);
  if (!named) {
    const Property* p = node.find("material");
    throw SceneError(p ? p->loc : node.loc, "unknown conductor material '" + material + "' for " +
                                                node.describe() + "; known names: " + known_metal_names());
  }
  // Mitsuba 0.6: eta and k override the material; both are relative to the exterior medium.
  float ext_eta = read_ior(node, "ext_eta", "air");
  if (!(ext_eta > 0.f)) {
    const Property* p = node.find("ext_eta");
    throw SceneError(p ? p->loc : node.loc, node.describe() + ": ext_eta must be positive");
  }
  ConductorIor ior;
  ior.eta = node.get_color("eta", named->eta) / ext_eta;
  ior.k = node.get_color("k", named->k) / ext_eta;
  return ior;
}

std::shared_ptr<Bsdf> make_conductor_bsdf(ConductorIor ior, std::shared_ptr<const Texture> specular_reflectance) {
  return std::make_shared<ConductorBsdf>(ior, std::move(specular_reflectance));
}

std::shared_ptr<Bsdf> make_conductor(const SceneNode& node, LoadContext& ctx) {
  ConductorIor ior = read_conductor_ior(node);
  return make_conductor_bsdf(ior, ctx.texture(node, "specular_reflectance", Rgb(1.f)));
}

}  // namespace tessera
