// Mitsuba 0.6's `blendbsdf`: a linear blend of two BSDFs by a weight that may be a texture.
// eval and pdf are the weighted sums. A sample comes from one component chosen by the weight; a
// non-delta sample then gets the blend's full eval over the blend's full pdf, exactly as Mitsuba
// adds the other component's eval and pdf in that direction (so the weight stays MIS-consistent).
// A delta sample cannot be evaluated by the other component through our interface (eval/pdf are
// 0 for delta lobes), so it keeps its own weight with the choice probability folded into its pdf:
// Mitsuba's result too unless both components have a delta lobe in the very same direction.
#include "tessera/bsdf/blendbsdf.h"

#include "tessera/core/check.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

// Largest float below 1: a remapped lobe-choice number must stay in [0, 1).
constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

class BlendBsdf final : public Bsdf {
 public:
  BlendBsdf(std::shared_ptr<const Texture> weight, const Bsdf* first, const Bsdf* second)
      : weight_(std::move(weight)), bsdfs_{first, second} {
    TESSERA_CHECK(weight_ && first && second);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    const float w = weight(si);
    return bsdfs_[0]->eval(si, wo, wi) * (1.f - w) + bsdfs_[1]->eval(si, wo, wi) * w;
  }

  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    const float w = weight(si);
    return bsdfs_[0]->pdf(si, wo, wi) * (1.f - w) + bsdfs_[1]->pdf(si, wo, wi) * w;
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    const float w1 = weight(si);
    const float weights[2] = {1.f - w1, w1};
    int entry;
    if (u1 < weights[0]) {
      entry = 0;
      u1 /= weights[0];
    } else {
      entry = 1;
      u1 = (u1 - weights[0]) / weights[1];
    }
    u1 = std::min(u1, kOneMinusEpsilon);
    if (!bsdfs_[entry]->sample(si, wo, u1, u2, out)) return false;
    if (out.delta) {
      out.pdf *= weights[entry];
      return out.pdf > 0.f;
    }
    const int other = 1 - entry;
    // The chosen component's eval is its weight times its pdf (Mitsuba's result *= pdf).
    Rgb f = out.weight * (out.pdf * weights[entry]);
    float pdf = out.pdf * weights[entry];
    if (weights[other] > 0.f) {
      f += bsdfs_[other]->eval(si, wo, out.wi) * weights[other];
      pdf += bsdfs_[other]->pdf(si, wo, out.wi) * weights[other];
    }
    if (!(pdf > 0.f) || !std::isfinite(pdf)) return false;
    out.weight = f / pdf;
    out.pdf = pdf;
    return true;
  }

  bool is_delta() const override { return bsdfs_[0]->is_delta() && bsdfs_[1]->is_delta(); }
  float roughness(const SurfaceInteraction& si) const override {
    const float w = weight(si);
    return std::max(w < 1.f ? bsdfs_[0]->roughness(si) : 0.f, w > 0.f ? bsdfs_[1]->roughness(si) : 0.f);
  }
  bool has_opacity() const override { return bsdfs_[0]->has_opacity() || bsdfs_[1]->has_opacity(); }
  float opacity(const SurfaceInteraction& si) const override {
    const float w = weight(si);
    return bsdfs_[0]->opacity(si) * (1.f - w) + bsdfs_[1]->opacity(si) * w;
  }

 private:
  float weight(const SurfaceInteraction& si) const { return std::clamp(weight_->eval_1(si), 0.f, 1.f); }

  std::shared_ptr<const Texture> weight_;
  const Bsdf* bsdfs_[2];
};

}  // namespace

std::shared_ptr<Bsdf> make_blend_bsdf(std::shared_ptr<const Texture> weight, const Bsdf* first, const Bsdf* second) {
  return std::make_shared<BlendBsdf>(std::move(weight), first, second);
}

std::shared_ptr<Bsdf> make_blendbsdf(const SceneNode& node, LoadContext& ctx) {
  auto nested = node.children_with_tag("bsdf");
  if (nested.size() != 2)
    throw SceneError(node.loc, node.describe() + ": expected two nested BSDFs, found " + std::to_string(nested.size()));
  auto weight = ctx.texture(node, "weight", Rgb(0.5f));
  return make_blend_bsdf(std::move(weight), ctx.bsdf(nested[0]), ctx.bsdf(nested[1]));
}

}  // namespace tessera
