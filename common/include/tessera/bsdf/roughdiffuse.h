// Mitsuba 0.6's `roughdiffuse` (Oren–Nayar) and `phong` (modified, energy-normalised Phong),
// constructible without a scene file (tests, tools).
#pragma once

#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// Oren–Nayar reflector. `alpha` is Beckmann-style RMS roughness (its eval_1, i.e. the channel
/// average as in Mitsuba); the model uses sigma = alpha / sqrt(2). `fast_approx` selects the
/// simple qualitative model (A + B max(0, cos dphi) sin a tan b), otherwise the full model with
/// the interreflection term is used. One-sided; cosine-weighted sampling.
std::shared_ptr<Bsdf> make_roughdiffuse_bsdf(std::shared_ptr<const Texture> reflectance,
                                             std::shared_ptr<const Texture> alpha, bool fast_approx);

/// Modified Phong: diffuse/pi + specular * (n+2)/(2 pi) cos^n(angle to the mirror direction).
/// The lobe is sampled with probability `specular_sampling_weight` (Mitsuba: luminance of the
/// specular mean over the sum of both means), the diffuse lobe otherwise; pdf() mixes both.
/// No energy-conservation rescaling here; the XML factory does it (as Mitsuba's configure()).
std::shared_ptr<Bsdf> make_phong_bsdf(std::shared_ptr<const Texture> diffuse_reflectance,
                                      std::shared_ptr<const Texture> specular_reflectance,
                                      std::shared_ptr<const Texture> exponent,
                                      float specular_sampling_weight);

/// `texture` times a constant (Mitsuba's ensureEnergyConservation wraps textures in a `scale`).
std::shared_ptr<const Texture> make_scaled_texture(std::shared_ptr<const Texture> texture, float scale);

/// Mitsuba's choice of the specular sampling weight from the two reflectances' means.
float phong_specular_sampling_weight(const Texture& diffuse_reflectance, const Texture& specular_reflectance);

}  // namespace tessera
