// Smooth dielectric interfaces (Mitsuba 0.6 `dielectric`, `thindielectric`, `plastic`), constructible
// without a scene file (tests, tools). All take eta = int_ior / ext_ior, with the interior below
// the surface (local -z).
#pragma once

#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// Mitsuba's `dielectric`: a delta reflection (probability F) and a delta refraction (1 - F), seen
/// from either side. Radiance convention: camera paths carry radiance, so a refracted sample's
/// weight is scaled by (eta_wo / eta_wi)^2, i.e. 1/eta^2 entering and eta^2 leaving.
std::shared_ptr<Bsdf> make_dielectric_bsdf(float eta, std::shared_ptr<const Texture> specular_reflectance,
                                           std::shared_ptr<const Texture> specular_transmittance);

/// Mitsuba's `thindielectric`: a thin slab; reflectance R' = R + T^2 R / (1 - R^2) sums the
/// inter-reflections, the rest passes straight through (wi = -wo), no radiance scaling.
std::shared_ptr<Bsdf> make_thindielectric_bsdf(float eta, std::shared_ptr<const Texture> specular_reflectance,
                                               std::shared_ptr<const Texture> specular_transmittance);

/// Mitsuba 0.6's smooth `plastic`: a Fresnel delta coat over a Lambertian base, with the internal
/// reflections between the two summed analytically (fdr term); `nonlinear` keeps the colour shift
/// of that sum. One-sided (front only). eval()/pdf() cover the diffuse part only.
std::shared_ptr<Bsdf> make_plastic_bsdf(float eta, std::shared_ptr<const Texture> diffuse_reflectance,
                                        std::shared_ptr<const Texture> specular_reflectance, bool nonlinear);

/// Hemispherical average of the Fresnel reflectance, 2 * integral of F(cos) cos dcos (Mitsuba's
/// fresnelDiffuseReflectance, numerical form), for light arriving from a medium of relative IOR eta.
float fresnel_diffuse_reflectance(float eta);

}  // namespace tessera
