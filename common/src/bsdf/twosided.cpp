#include "tessera/bsdf/diffuse.h"

#include "tessera/core/check.h"
#include "tessera/scene/load_context.h"

namespace tessera {
namespace {

Vec3 mirror_z(Vec3 w) { return {w.x, w.y, -w.z}; }

class TwoSidedBsdf final : public Bsdf {
 public:
  TwoSidedBsdf(const Bsdf* front, const Bsdf* back) : front_(front), back_(back) {
    TESSERA_CHECK(front_ != nullptr && back_ != nullptr);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (wo.z < 0.f) return back_->eval(si, mirror_z(wo), mirror_z(wi));
    return front_->eval(si, wo, wi);
  }

  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (wo.z < 0.f) return back_->pdf(si, mirror_z(wo), mirror_z(wi));
    return front_->pdf(si, wo, wi);
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    if (wo.z < 0.f) {
      if (!back_->sample(si, mirror_z(wo), u1, u2, out)) return false;
      out.wi = mirror_z(out.wi);
      return true;
    }
    return front_->sample(si, wo, u1, u2, out);
  }

  bool is_delta() const override { return front_->is_delta() && back_->is_delta(); }
  float roughness(const SurfaceInteraction& si) const override {
    return dot(si.wo, si.shading.n) < 0.f ? back_->roughness(si) : front_->roughness(si);
  }
  bool has_opacity() const override { return front_->has_opacity() || back_->has_opacity(); }
  float opacity(const SurfaceInteraction& si) const override {
    return dot(si.wo, si.shading.n) < 0.f ? back_->opacity(si) : front_->opacity(si);
  }

 private:
  const Bsdf* front_;
  const Bsdf* back_;
};

}  // namespace

std::shared_ptr<Bsdf> make_twosided_bsdf(const Bsdf* front, const Bsdf* back) {
  return std::make_shared<TwoSidedBsdf>(front, back ? back : front);
}

std::shared_ptr<Bsdf> make_twosided(const SceneNode& node, LoadContext& ctx) {
  auto nested = node.children_with_tag("bsdf");
  if (nested.empty() || nested.size() > 2)
    throw SceneError(node.loc, node.describe() + ": expected one or two nested BSDFs, found " +
                                   std::to_string(nested.size()));
  const Bsdf* front = ctx.bsdf(nested[0]);
  const Bsdf* back = nested.size() == 2 ? ctx.bsdf(nested[1]) : front;
  return make_twosided_bsdf(front, back);
}

}  // namespace tessera
