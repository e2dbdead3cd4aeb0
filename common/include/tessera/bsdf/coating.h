// Mitsuba 0.6's `coating` and `roughcoating`: a dielectric layer over a nested BSDF, constructible
// without a scene file (tests, tools). eta = int_ior / ext_ior (the layer below the interface).
#pragma once

#include "tessera/bsdf/microfacet.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// Smooth interface: a delta Fresnel reflection (times `specular_reflectance`) plus `nested` seen
/// through the refracting interface, attenuated by both Fresnel transmittances and by the
/// absorption exp(-sigma_a thickness (1/cos_i' + 1/cos_o')) along the refracted directions.
/// Light internally reflected inside the layer is dropped, as in Mitsuba. Both sides of the
/// surface are handled as Mitsuba does (the nested BSDF sees directions below the surface then).
/// `nested` must outlive the result. eta == 1 is accepted here (an invisible interface).
std::shared_ptr<Bsdf> make_coating_bsdf(float eta, float thickness, std::shared_ptr<const Texture> sigma_a,
                                        std::shared_ptr<const Texture> specular_reflectance, const Bsdf* nested);

/// Rough interface (isotropic alpha, constant or textured): microfacet reflection plus `nested`
/// seen through the interface as if it were smooth, attenuated by the rough transmittance
/// T(cos_o) T(cos_i) instead of the Fresnel factors (Mitsuba's approximation). The transmittance
/// is tabulated at construction: for a constant alpha one table (tens of ms); for a textured alpha
/// tables at nine roughness values in [1e-3, 1] (clamped beyond), a few hundred ms.
std::shared_ptr<Bsdf> make_roughcoating_bsdf(MicrofacetType type, std::shared_ptr<const Texture> alpha, float eta,
                                             float thickness, std::shared_ptr<const Texture> sigma_a,
                                             std::shared_ptr<const Texture> specular_reflectance,
                                             const Bsdf* nested);

}  // namespace tessera
