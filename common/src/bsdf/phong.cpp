// Mitsuba 0.6's `phong`: the modified, energy-normalised Phong model of Lafortune and Willems
// (1994), a Lambertian base plus the lobe (n+2)/(2 pi) cos^n(angle between wi and the mirror
// direction of wo). The lobe is importance-sampled exactly for cos^n ((n+1)/(2 pi) cos^n) about the
// mirror direction; samples below the surface are rejected, which is why pdf() integrates to < 1.
#include "tessera/bsdf/roughdiffuse.h"

#include "tessera/core/check.h"
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tessera {
namespace {

class PhongBsdf final : public Bsdf {
 public:
  PhongBsdf(std::shared_ptr<const Texture> diffuse, std::shared_ptr<const Texture> specular,
            std::shared_ptr<const Texture> exponent, float specular_weight)
      : diffuse_(std::move(diffuse)),
        specular_(std::move(specular)),
        exponent_(std::move(exponent)),
        specular_weight_(specular_weight) {
    TESSERA_CHECK(diffuse_ != nullptr && specular_ != nullptr && exponent_ != nullptr);
    TESSERA_CHECK(specular_weight_ >= 0.f && specular_weight_ <= 1.f);
  }

  Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return {};
    Rgb result = diffuse_->eval(si) * kInvPi;
    const float cos_alpha = dot(wi, reflect(wo));
    if (cos_alpha > 0.f) {
      const float n = exponent_->eval_1(si);
      result += specular_->eval(si) * ((n + 2.f) * (0.5f * kInvPi) * std::pow(cos_alpha, n));
    }
    return result * cos_theta(wi);
  }

  float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const override {
    if (cos_theta(wo) <= 0.f || cos_theta(wi) <= 0.f) return 0.f;
    const float diffuse_pdf = cosine_hemisphere_pdf(cos_theta(wi));
    float specular_pdf = 0.f;
    const float cos_alpha = dot(wi, reflect(wo));
    if (cos_alpha > 0.f) {
      const float n = exponent_->eval_1(si);
      specular_pdf = std::pow(cos_alpha, n) * (n + 1.f) * (0.5f * kInvPi);
    }
    return specular_weight_ * specular_pdf + (1.f - specular_weight_) * diffuse_pdf;
  }

  bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const override {
    if (cos_theta(wo) <= 0.f) return false;
    Vec3 wi;
    if (u1 < specular_weight_) {
      const float n = exponent_->eval_1(si);
      const float cos_alpha = std::pow(u2.y, 1.f / (n + 1.f));
      const float sin_alpha = std::sqrt(std::max(0.f, 1.f - cos_alpha * cos_alpha));
      const float phi = 2.f * kPi * u2.x;
      wi = normalize(Frame(reflect(wo)).to_world(
          Vec3(sin_alpha * std::cos(phi), sin_alpha * std::sin(phi), cos_alpha)));
      if (cos_theta(wi) <= 0.f) return false;
    } else {
      wi = square_to_cosine_hemisphere(u2);
    }
    const float p = pdf(si, wo, wi);
    if (!(p > 0.f)) return false;
    out.wi = wi;
    out.pdf = p;
    out.weight = eval(si, wo, wi) / p;
    out.delta = false;
    out.eta = 1.f;
    return true;
  }

  // (A Phong lobe of exponent n is about as wide as a Beckmann lobe of alpha sqrt(2 / (n + 2)).)
  float roughness(const SurfaceInteraction& si) const override {
    if (specular_weight_ < 1.f) return 1.f;
    return std::clamp(std::sqrt(2.f / (std::max(exponent_->eval_1(si), 0.f) + 2.f)), 0.f, 1.f);
  }

 private:
  static Vec3 reflect(Vec3 w) { return {-w.x, -w.y, w.z}; }

  std::shared_ptr<const Texture> diffuse_;
  std::shared_ptr<const Texture> specular_;
  std::shared_ptr<const Texture> exponent_;
  float specular_weight_;
};

/// Scales a texture by a constant (Mitsuba's energy-conservation fix-up).
class ScaledTexture final : public Texture {
 public:
  ScaledTexture(std::shared_ptr<const Texture> inner, float scale) : inner_(std::move(inner)), scale_(scale) {}
  Rgb eval(const SurfaceInteraction& si) const override { return inner_->eval(si) * scale_; }
  float eval_1(const SurfaceInteraction& si) const override { return inner_->eval_1(si) * scale_; }
  Rgb mean() const override { return inner_->mean() * scale_; }

 private:
  std::shared_ptr<const Texture> inner_;
  float scale_;
};

}  // namespace

float phong_specular_sampling_weight(const Texture& diffuse_reflectance, const Texture& specular_reflectance) {
  const float d = diffuse_reflectance.mean().luminance(), s = specular_reflectance.mean().luminance();
  // Mitsuba divides 0 by 0 here for an all-black material; any weight is right then.
  if (!(d + s > 0.f)) return 0.5f;
  return std::clamp(s / (d + s), 0.f, 1.f);
}

std::shared_ptr<const Texture> make_scaled_texture(std::shared_ptr<const Texture> texture, float scale) {
  return std::make_shared<ScaledTexture>(std::move(texture), scale);
}

std::shared_ptr<Bsdf> make_phong_bsdf(std::shared_ptr<const Texture> diffuse_reflectance,
                                      std::shared_ptr<const Texture> specular_reflectance,
                                      std::shared_ptr<const Texture> exponent, float specular_sampling_weight) {
  return std::make_shared<PhongBsdf>(std::move(diffuse_reflectance), std::move(specular_reflectance),
                                     std::move(exponent), specular_sampling_weight);
}

std::shared_ptr<Bsdf> make_phong(const SceneNode& node, LoadContext& ctx) {
  std::shared_ptr<const Texture> diffuse = ctx.texture(node, "diffuse_reflectance", Rgb(0.5f));
  std::shared_ptr<const Texture> specular = ctx.texture(node, "specular_reflectance", Rgb(0.2f));
  std::shared_ptr<const Texture> exponent = ctx.texture(node, "exponent", Rgb(30.f));
  // Mitsuba's ensureEnergyConservation(specular, diffuse): if the two reflectances can sum to more
  // than 1 in some channel, both are scaled by 0.99 / max. Mitsuba uses the textures' maxima; the
  // Texture interface offers means, which are the maxima for constant values (the usual case).
  const Rgb sum = diffuse->mean() + specular->mean();
  const float max_sum = std::max({sum.r, sum.g, sum.b});
  if (node.get_bool("ensure_energy_conservation", true) && max_sum > 1.f) {
    const float scale = 0.99f / max_sum;
    std::ostringstream msg;
    msg << "phong: specular + diffuse reflectance reaches " << max_sum
        << " (> 1, not energy conserving); both scaled by " << scale
        << " as Mitsuba does (ensureEnergyConservation=false prevents this)";
    ctx.warn(node.loc, msg.str());
    diffuse = make_scaled_texture(diffuse, scale);
    specular = make_scaled_texture(specular, scale);
  }
  const float weight = phong_specular_sampling_weight(*diffuse, *specular);
  return make_phong_bsdf(std::move(diffuse), std::move(specular), std::move(exponent), weight);
}

}  // namespace tessera
