// Mitsuba 0.6 `roughplastic`: a rough dielectric coat (microfacet reflection) over a Lambertian base.
#pragma once

#include "tessera/bsdf/microfacet.h"
#include "tessera/bsdf/rough_transmittance.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// Coat of relative IOR `eta` (inside over outside) with a constant, isotropic roughness `alpha`.
/// Builds its rough-transmittance tables at construction (a few ms); see roughplastic.cpp.
std::shared_ptr<Bsdf> make_roughplastic_bsdf(MicrofacetType type, float alpha, float eta,
                                             std::shared_ptr<const Texture> diffuse_reflectance,
                                             std::shared_ptr<const Texture> specular_reflectance, bool nonlinear);

}  // namespace tessera
