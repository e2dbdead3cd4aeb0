// Mitsuba 0.6's `roughcoating`: `coating` with a rough interface -- a deliberately approximate
// model. The interface reflects as a microfacet surface,
//   f_s cos_i = specular_reflectance F(wo.h) D(h) G(wo, wi, h) / (4 |cos_o|),
// and the nested BSDF is seen through it as if it were smooth (directions refracted by Snell's law
// about the macro normal), attenuated by the rough interface's transmittance T(cos) -- the
// fraction of light it lets through, Mitsuba's precomputed rtrans tables, here built at load by
// bsdf/rough_transmittance.h -- instead of the Fresnel factors:
//   f_n(wo', wi') T(|cos_o|) T(|cos_i|) exp(-sigma_a d (1/|cos_o'| + 1/|cos_i'|)) cos_i / (eta^2 cos_i').
// The specular lobe is two-sided as in Mitsuba (both directions on one side). The interface lobe
// is chosen with probability 1 - T(|cos_o|), reallocated by the absorption weight as in `coating`;
// a non-delta sample's weight is the full eval over the full pdf (Mitsuba's "guard against
// numerical imprecisions"). Deliberate differences: from below, the micro-normal is sampled for
// the mirrored direction (Mitsuba feeds a below-horizon direction to its sampler; same pdf()); and
// a delta sample of the nested BSDF keeps the 1/(1 - P(interface)) of its choice, which Mitsuba's
// discrete-measure pdf drops.
#include "tessera/bsdf/coating.h"

#include "coating_util.h"
#include "tessera/bsdf/microfacet_params.h"
#include "tessera/bsdf/rough_transmittance.h"
#include "tessera/core/check.h"
#include "tessera/core/frame.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tessera {
namespace {

constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

// Roughness nodes of the transmittance tables for a textured alpha. T is smooth in alpha; with
// piecewise quadratic interpolation between these it stays within ~1e-3 (relative) of the table
// built for the exact alpha (tests/bsdf/roughcoating_test.cpp). Beyond 1 it is clamped.
const std::vector<float>& textured_alpha_nodes() {
  static const std::vector<float> nodes = {1e-3f, 0.05f, 0.1f, 0.2f, 0.3f, 0.45f, 0.6f, 0.8f, 1.f};
  return nodes;
}

std::vector<float> alpha_nodes(const Texture& alpha) {
  if (dynamic_cast<const ConstantTexture*>(&alpha) != nullptr) return {alpha.mean().average()};
  return textured_alpha_nodes();
}

class RoughCoatingBsdf final : public Bsdf {
 public:
  RoughCoatingBsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha, float eta, float thickness,
                   std::shared_ptr<const Texture> sigma_a, std::shared_ptr<const Texture> specular,
                   const Bsdf* nested)
      : type_(type), alpha_(std::move(alpha)), eta_(eta), inv_eta2_(1.f / (eta * eta)), thickness_(thickness),
        sigma_a_(std::move(sigma_a)), specular_(std::move(specular)), nested_(nested),
        transmittance_(type, alpha_nodes(*alpha_), eta) {
    TESSERA_CHECK(eta > 0.f && sigma_a_ && specular_ && nested_);
    specular_weight_ = coating::specular_sampling_weight(*sigma_a_, thickness_);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    const float alpha = alpha_->eval_1(si);
    return specular_part(si, MicrofacetDistribution(type_, alpha), wo, wi) + nested_part(si, alpha, wo, wi);
  }

  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    const float alpha = alpha_->eval_1(si);
    const float p_spec = prob_specular(wo, alpha);
    float result = 0.f;
    if (wo.z * wi.z > 0.f) {
      const float s = wo.z > 0.f ? 1.f : -1.f;
      const Vec3 a = s * wo, b = s * wi, h = normalize(a + b);
      const float b_h = dot(b, h);
      if (b_h > 0.f) result = MicrofacetDistribution(type_, alpha).pdf_m(a, h) / (4.f * b_h) * p_spec;
    }
    Vec3 wo_in, wi_in;
    float f;
    if (coating::refract(wo, eta_, wo_in, f) && coating::refract(wi, eta_, wi_in, f))
      result += nested_->pdf(si, wo_in, wi_in) * inv_eta2_ * wi.z / wi_in.z * (1.f - p_spec);
    return result;
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    if (wo.z == 0.f) return false;
    const float alpha = alpha_->eval_1(si);
    const float p_spec = prob_specular(wo, alpha);
    Vec3 wi;
    float f;
    if (u1 < p_spec) {
      const float s = wo.z > 0.f ? 1.f : -1.f;
      const Vec3 a = s * wo;
      MicrofacetSample ms;
      if (!MicrofacetDistribution(type_, alpha).sample_m(a, u2, ms)) return false;
      const Vec3 b = 2.f * dot(a, ms.m) * ms.m - a;
      if (b.z <= 0.f) return false;
      wi = s * b;
      out.eta = 1.f;
    } else {
      Vec3 wo_in;
      if (!coating::refract(wo, eta_, wo_in, f)) return false;
      BsdfSample ns;
      const float u1n = std::min((u1 - p_spec) / (1.f - p_spec), kOneMinusEpsilon);
      if (!nested_->sample(si, wo_in, u1n, u2, ns)) return false;
      if (!coating::refract(ns.wi, 1.f / eta_, wi, f)) return false;  // reflected back into the layer
      out.eta = ns.eta;
      if (ns.delta) {
        out.wi = wi;
        out.weight = ns.weight * coating::absorption(sigma_a_->eval(si), thickness_, wo_in, ns.wi) *
                     (transmittance_.eval(std::abs(wo.z), alpha) * transmittance_.eval(std::abs(wi.z), alpha) /
                      (1.f - p_spec));
        out.pdf = ns.pdf * (1.f - p_spec);
        out.delta = true;
        return out.pdf > 0.f;
      }
    }
    const float pdf = this->pdf(si, wo, wi);
    if (!(pdf > 0.f) || !std::isfinite(pdf)) return false;
    out.wi = wi;
    out.pdf = pdf;
    out.weight = eval(si, wo, wi) / pdf;
    out.delta = false;
    return true;
  }

  bool has_opacity() const override { return nested_->has_opacity(); }
  float opacity(const SurfaceInteraction& si) const override { return nested_->opacity(si); }
  float roughness(const SurfaceInteraction& si) const override {
    return std::max(std::clamp(alpha_->eval_1(si), 0.f, 1.f), nested_->roughness(si));
  }

 private:
  float prob_specular(Vec3 wo, float alpha) const {
    return coating::prob_specular(1.f - transmittance_.eval(std::abs(wo.z), alpha), specular_weight_);
  }

  Rgb specular_part(const SurfaceInteraction& si, const MicrofacetDistribution& distr, Vec3 wo, Vec3 wi) const {
    if (!(wo.z * wi.z > 0.f)) return {};
    // Seen from below, both directions are mirrored through the surface (Mitsuba flips h instead).
    const float s = wo.z > 0.f ? 1.f : -1.f;
    const Vec3 a = s * wo, b = s * wi, h = normalize(a + b);
    const float d = distr.D(h);
    if (!(d > 0.f)) return {};
    const float f = fresnel_dielectric(std::abs(dot(a, h)), eta_);
    return specular_->eval(si) * (f * d * distr.G(a, b, h) / (4.f * a.z));
  }

  Rgb nested_part(const SurfaceInteraction& si, float alpha, Vec3 wo, Vec3 wi) const {
    Vec3 wo_in, wi_in;
    float f;
    if (!coating::refract(wo, eta_, wo_in, f) || !coating::refract(wi, eta_, wi_in, f)) return {};
    const Rgb n = nested_->eval(si, wo_in, wi_in);
    if (n.is_black()) return {};
    const float t = transmittance_.eval(std::abs(wo.z), alpha) * transmittance_.eval(std::abs(wi.z), alpha);
    return n * coating::absorption(sigma_a_->eval(si), thickness_, wo_in, wi_in) * (t * inv_eta2_ * wi.z / wi_in.z);
  }

  MicrofacetType type_;
  std::shared_ptr<const Texture> alpha_;
  float eta_, inv_eta2_, thickness_;
  float specular_weight_ = 0.5f;
  std::shared_ptr<const Texture> sigma_a_, specular_;
  const Bsdf* nested_;
  RoughTransmittance transmittance_;
};

}  // namespace

std::shared_ptr<Bsdf> make_roughcoating_bsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha, float eta,
                                             float thickness, std::shared_ptr<const Texture> sigma_a,
                                             std::shared_ptr<const Texture> specular_reflectance,
                                             const Bsdf* nested) {
  return std::make_shared<RoughCoatingBsdf>(type, std::move(alpha), eta, thickness, std::move(sigma_a),
                                            std::move(specular_reflectance), nested);
}

std::shared_ptr<Bsdf> make_roughcoating(const SceneNode& node, LoadContext& ctx) {
  auto nested = node.children_with_tag("bsdf");
  if (nested.size() != 1)
    throw SceneError(node.loc, node.describe() + ": expected one nested BSDF, found " + std::to_string(nested.size()));
  const MicrofacetType type = read_microfacet_type(node, ctx);
  const MicrofacetAlpha alpha = read_microfacet_alpha(node, ctx);
  if (alpha.u != alpha.v) {
    const bool same_constant = dynamic_cast<const ConstantTexture*>(alpha.u.get()) &&
                               dynamic_cast<const ConstantTexture*>(alpha.v.get()) &&
                               alpha.u->mean() == alpha.v->mean();
    if (!same_constant)
      throw SceneError(node.loc, node.describe() + ": anisotropic roughness is not supported (as in Mitsuba)");
  }
  if (!(alpha.u->mean().average() > 0.f)) throw SceneError(node.loc, node.describe() + ": alpha must be positive");
  const float eta = coating::read_coating_eta(node);
  const float thickness = node.get_float("thickness", 1.f);
  auto sigma_a = ctx.texture(node, "sigma_a", Rgb(0.f));
  auto specular = coating::read_specular_reflectance(node, ctx);
  return make_roughcoating_bsdf(type, alpha.u, eta, thickness, std::move(sigma_a), std::move(specular),
                                ctx.bsdf(nested[0]));
}

}  // namespace tessera
