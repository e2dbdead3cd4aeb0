// Path guiding's choice of the next direction: one-sample MIS of the BSDF's own sampling and a
// learned distribution of incident radiance (guiding/directional_tree.h, in world space). With
// probability `bsdf_fraction` the BSDF samples, otherwise the guide; the pdf is the mixture's,
//   pdf(wi) = bsdf_fraction * bsdf.pdf(wi) + (1 - bsdf_fraction) * guide.pdf(wi)   (solid angle),
// and the weight eval(wi) / pdf(wi) (eval includes the cosine, bsdf.h). A delta lobe the BSDF picks
// is outside the mixture: its pdf and weight are the BSDF's, for the probability of choosing the
// BSDF. The lobe dimension `u_lobe` also makes the choice (rescaled for the BSDF), so guiding
// draws no dimension the unguided path does not (sampler.h). Where the fraction is 1 (a leaf that
// learned the guide does not help, as half of cornell-box's do) the mixture is the BSDF's own
// sampling, and neither function descends the guide for it. Hot path: no throw, no allocation.
#pragma once

#include "tessera/guiding/directional_tree.h"
#include "tessera/render/bsdf.h"

namespace tessera {

/// The two densities the mixture combines at a sampled direction (solid angle), and the
/// direction's point on the guide's square (DirectionalTree), where a training record goes.
struct MixturePdfs {
  float bsdf = 0.f, guide = 0.f;
  Vec2 square;
};

/// The least roughness (Bsdf::roughness) of a lobe the mixture samples; narrower lobes are left to
/// the BSDF alone. The guide learns the incident radiance, not its product with the BSDF: under a
/// glossy lobe that product has the lobe's shape, which the BSDF samples nearly in proportion, and
/// a guided direction beside the lobe is wasted (a deviation from Müller's plugin, which guides
/// every lobe that is not a delta: on veach-mis's plates, of alpha 0.01–0.25, that tripled the
/// error, docs/performance.md).
inline constexpr float kMinGuidedRoughness = 0.3f;

/// Whether a path guide samples the next direction at `si`: a BSDF rough enough to gain from it.
inline bool guides_lobe(const Bsdf& bsdf, const SurfaceInteraction& si) {
  return !bsdf.is_delta() && bsdf.roughness(si) >= kMinGuidedRoughness;
}

/// Samples `out` (wi in the local frame of `si`) from the mixture; false when nothing was sampled.
/// The weight is black for a guided direction where the BSDF is zero. A guided direction's `eta`
/// is 1 (only Russian roulette reads it). `parts`, if given, receives the mixture's components at
/// a non-delta direction (for learning the fraction, guiding/bsdf_fraction.h).
bool sample_guided(const Bsdf& bsdf, const SurfaceInteraction& si, Vec3 wo, const DirectionalTree& guide,
                   float bsdf_fraction, float u_lobe, Vec2 u_dir, BsdfSample& out, MixturePdfs* parts = nullptr);
/// The mixture's solid-angle density of the non-delta direction `wi` (local frame).
float guided_pdf(const Bsdf& bsdf, const SurfaceInteraction& si, Vec3 wo, Vec3 wi, const DirectionalTree& guide,
                 float bsdf_fraction);

}  // namespace tessera
