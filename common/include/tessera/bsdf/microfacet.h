// Microfacet normal distributions as Mitsuba 0.6 defines them (src/libcore/microfacet.h): Beckmann,
// GGX (Trowbridge-Reitz) and Phong, isotropic or anisotropic, with Smith shadowing-masking.
//
// All directions are in the local shading frame (macro-surface normal on +z). A distribution is a
// small value type, cheap to build per shading point (rough BSDFs with a textured alpha build one per
// hit). Used by roughconductor, and meant for roughdielectric / roughplastic as well.
//
// Sampling:
//  - GGX: distribution of visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible
//    Normals"), pdf_m(wi, m) = G1(wi, m) * max(0, wi.m) * D(m) / cos(wi).
//  - Beckmann, Phong: D(m) cos(theta_m) in closed form (Walter et al. 2007 / Mitsuba's sampleAll),
//    pdf_m(wi, m) = D(m) cos(theta_m), independent of wi. Mitsuba samples Beckmann's visible normals
//    by a numerical inversion; the closed form is used here because its pdf is exact.
// In every case sample_m() reports exactly the density pdf_m() returns.
#pragma once

#include "tessera/core/vec.h"

#include <algorithm>
#include <optional>
#include <string_view>

namespace tessera {

enum class MicrofacetType { Beckmann, Ggx, Phong };

/// "beckmann", "ggx", "phong" (Mitsuba's names); nullopt otherwise.
std::optional<MicrofacetType> parse_microfacet_type(std::string_view name);

struct MicrofacetSample {
  Vec3 m;            // sampled micro-normal, m.z > 0
  float pdf = 0.f;   // density of m with respect to solid angle (== pdf_m(wi, m))
};

class MicrofacetDistribution {
 public:
  /// Roughness alpha (Beckmann's rms slope, GGX's alpha; for Phong converted to the exponent
  /// 2 / alpha^2 - 2 as Mitsuba 0.6 does). Clamped to >= 1e-4 like Mitsuba.
  MicrofacetDistribution(MicrofacetType type, float alpha_u, float alpha_v);
  MicrofacetDistribution(MicrofacetType type, float alpha) : MicrofacetDistribution(type, alpha, alpha) {}

  MicrofacetType type() const { return type_; }
  float alpha_u() const { return alpha_u_; }
  float alpha_v() const { return alpha_v_; }
  bool is_isotropic() const { return alpha_u_ == alpha_v_; }
  /// Bsdf::roughness of a lobe of this distribution: the smaller alpha, at most 1.
  float roughness() const { return std::min(std::min(alpha_u_, alpha_v_), 1.f); }
  /// True when sample_m() draws visible normals (its pdf then depends on wi).
  bool samples_visible_normals() const { return type_ == MicrofacetType::Ggx; }

  /// Normal distribution D(m) (1/sr); integral of D(m) cos(theta_m) dm over the hemisphere is 1.
  float D(Vec3 m) const;
  /// Smith's monodirectional shadowing G1(v, m): 0 when v and m are on opposite sides relative to
  /// the macro-surface (Mitsuba's check dot(v, m) * cos(v) <= 0).
  float G1(Vec3 v, Vec3 m) const;
  /// Separable shadowing-masking G1(wi, m) * G1(wo, m).
  float G(Vec3 wi, Vec3 wo, Vec3 m) const { return G1(wi, m) * G1(wo, m); }

  /// Samples a micro-normal for incident direction `wi` (wi.z > 0 required; callers below the
  /// surface flip wi first). Returns false (out.pdf = 0) when no normal could be drawn.
  bool sample_m(Vec3 wi, Vec2 u, MicrofacetSample& out) const;
  /// Density of sample_m(wi, .) producing m, per solid angle of m.
  float pdf_m(Vec3 wi, Vec3 m) const;

 private:
  /// Roughness along the azimuth of v (Mitsuba's projectRoughness).
  float project_roughness(Vec3 v) const;
  /// Phong exponent interpolated along the azimuth of m.
  float phong_exponent(Vec3 m) const;

  MicrofacetType type_;
  float alpha_u_, alpha_v_;
  float exponent_u_ = 0.f, exponent_v_ = 0.f;  // Phong only
};

}  // namespace tessera
