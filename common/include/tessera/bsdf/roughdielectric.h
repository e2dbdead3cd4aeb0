// Mitsuba 0.6's `roughdielectric`, constructible without a scene file (tests, tools).
#pragma once

#include "tessera/bsdf/microfacet.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// Rough interface between two dielectrics (Walter et al. 2007), seen from either side, eta =
/// int_ior / ext_ior with the interior below the surface (local -z). A micro-normal is sampled,
/// then reflection is chosen with probability F(wo.m), refraction otherwise. Refracted radiance is
/// scaled like the smooth `dielectric` (1/eta^2 entering, eta^2 leaving). `alpha_v` may be null
/// (isotropic). Alphas are evaluated at each hit (eval_1).
std::shared_ptr<Bsdf> make_roughdielectric_bsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha_u,
                                                std::shared_ptr<const Texture> alpha_v, float eta,
                                                std::shared_ptr<const Texture> specular_reflectance,
                                                std::shared_ptr<const Texture> specular_transmittance);

}  // namespace tessera
