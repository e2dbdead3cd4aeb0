// Mitsuba 0.6's `coating`: a smooth dielectric layer (varnish) over a nested BSDF, after Weidlich and
// Wilkie's "Arbitrarily Layered Micro-Facet Surfaces". With R = F(|cos|, eta) of each direction
// and ' marking a direction refracted into the layer:
//   reflection:  delta, specular_reflectance * R(wo)
//   nested:      f_n(wo', wi') (1 - R(wo)) (1 - R(wi)) exp(-sigma_a d (1/|cos wo'| + 1/|cos wi'|))
//                * cos_i / (eta^2 cos_i')
// where the last factor is the solid-angle compression of the refraction (dwi' = dwi cos_i /
// (eta^2 cos_i')) applied to the nested eval, which includes cos_i'. The pdf carries the same
// factor. Light reflected back down by the underside of the interface is dropped, as in Mitsuba.
// The lobe choice is Mitsuba's: probability R(wo) reallocated by a weight that favours the
// interface when the layer absorbs; the nested BSDF reuses the rescaled lobe-choice number.
#include "tessera/bsdf/coating.h"

#include "coating_util.h"
#include "tessera/bsdf/ior.h"
#include "tessera/bsdf/roughdiffuse.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tessera {

namespace coating {

std::shared_ptr<const Texture> read_specular_reflectance(const SceneNode& node, LoadContext& ctx) {
  std::shared_ptr<const Texture> tex = ctx.texture(node, "specular_reflectance", Rgb(1.f));
  const float max_refl = tex->mean().max_value();
  if (node.get_bool("ensure_energy_conservation", true) && max_refl > 1.f) {
    const float scale = 0.99f / max_refl;
    std::ostringstream msg;
    msg << node.describe() << ": specularReflectance reaches " << max_refl << " (> 1, not energy conserving); scaled by "
        << scale << " as Mitsuba does (ensureEnergyConservation=false prevents this)";
    ctx.warn(node.loc, msg.str());
    tex = make_scaled_texture(std::move(tex), scale);
  }
  return tex;
}

float read_coating_eta(const SceneNode& node) {
  const float int_ior = read_ior(node, "int_ior", "bk7");
  const float ext_ior = read_ior(node, "ext_ior", "air");
  if (!(int_ior > 0.f) || !(ext_ior > 0.f) || int_ior == ext_ior)
    throw SceneError(node.loc, node.describe() + ": int_ior and ext_ior must be positive and differ");
  return int_ior / ext_ior;
}

}  // namespace coating

namespace {

constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

class CoatingBsdf final : public Bsdf {
 public:
  CoatingBsdf(float eta, float thickness, std::shared_ptr<const Texture> sigma_a,
              std::shared_ptr<const Texture> specular, const Bsdf* nested)
      : eta_(eta), inv_eta2_(1.f / (eta * eta)), thickness_(thickness), sigma_a_(std::move(sigma_a)),
        specular_(std::move(specular)), nested_(nested) {
    TESSERA_CHECK(eta > 0.f && sigma_a_ && specular_ && nested_);
    specular_weight_ = coating::specular_sampling_weight(*sigma_a_, thickness_);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    Vec3 wo_in, wi_in;
    float r12, r21;
    if (!coating::refract(wo, eta_, wo_in, r12) || !coating::refract(wi, eta_, wi_in, r21)) return {};
    const Rgb f = nested_->eval(si, wo_in, wi_in);
    if (f.is_black()) return {};
    return f * coating::absorption(sigma_a_->eval(si), thickness_, wo_in, wi_in) *
           ((1.f - r12) * (1.f - r21) * inv_eta2_ * wi.z / wi_in.z);
  }

  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    Vec3 wo_in, wi_in;
    float r12, r21;
    if (!coating::refract(wo, eta_, wo_in, r12) || !coating::refract(wi, eta_, wi_in, r21)) return 0.f;
    const float p_nested = 1.f - coating::prob_specular(r12, specular_weight_);
    return nested_->pdf(si, wo_in, wi_in) * p_nested * inv_eta2_ * wi.z / wi_in.z;
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    Vec3 wo_in;
    float r12;
    const bool enters = coating::refract(wo, eta_, wo_in, r12);
    if (!enters) r12 = 1.f;
    const float p_spec = coating::prob_specular(r12, specular_weight_);
    if (u1 < p_spec) {
      out.wi = Vec3(-wo.x, -wo.y, wo.z);
      out.pdf = p_spec;
      out.weight = specular_->eval(si) * (r12 / p_spec);
      out.delta = true;
      out.eta = 1.f;
      return true;
    }
    if (!enters) return false;
    const float p_nested = 1.f - p_spec;
    BsdfSample ns;
    if (!nested_->sample(si, wo_in, std::min((u1 - p_spec) / p_nested, kOneMinusEpsilon), u2, ns)) return false;
    Vec3 wi;
    float r21;
    if (!coating::refract(ns.wi, 1.f / eta_, wi, r21)) return false;  // reflected back into the layer
    out.wi = wi;
    out.weight = ns.weight * coating::absorption(sigma_a_->eval(si), thickness_, wo_in, ns.wi) *
                 ((1.f - r12) * (1.f - r21) / p_nested);
    // A delta nested lobe stays a discrete probability; otherwise the density moves to wi's measure.
    out.pdf = ns.pdf * p_nested * (ns.delta ? 1.f : inv_eta2_ * wi.z / ns.wi.z);
    out.delta = ns.delta;
    out.eta = ns.eta;
    return out.pdf > 0.f && std::isfinite(out.pdf);
  }

  bool is_delta() const override { return nested_->is_delta(); }
  float roughness(const SurfaceInteraction& si) const override { return nested_->roughness(si); }
  bool has_opacity() const override { return nested_->has_opacity(); }
  float opacity(const SurfaceInteraction& si) const override { return nested_->opacity(si); }

 private:
  float eta_, inv_eta2_, thickness_;
  float specular_weight_ = 0.5f;
  std::shared_ptr<const Texture> sigma_a_, specular_;
  const Bsdf* nested_;
};

}  // namespace

std::shared_ptr<Bsdf> make_coating_bsdf(float eta, float thickness, std::shared_ptr<const Texture> sigma_a,
                                        std::shared_ptr<const Texture> specular_reflectance, const Bsdf* nested) {
  return std::make_shared<CoatingBsdf>(eta, thickness, std::move(sigma_a), std::move(specular_reflectance), nested);
}

std::shared_ptr<Bsdf> make_coating(const SceneNode& node, LoadContext& ctx) {
  auto nested = node.children_with_tag("bsdf");
  if (nested.size() != 1)
    throw SceneError(node.loc, node.describe() + ": expected one nested BSDF, found " + std::to_string(nested.size()));
  const float eta = coating::read_coating_eta(node);
  const float thickness = node.get_float("thickness", 1.f);
  auto sigma_a = ctx.texture(node, "sigma_a", Rgb(0.f));
  auto specular = coating::read_specular_reflectance(node, ctx);
  return make_coating_bsdf(eta, thickness, std::move(sigma_a), std::move(specular), ctx.bsdf(nested[0]));
}

}  // namespace tessera
