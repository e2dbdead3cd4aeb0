// Lambertian and two-sided BSDFs, constructible without a scene file (tests, tools).
#pragma once

#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// One-sided Lambertian reflector (Mitsuba's `diffuse`): zero unless wo and wi are both above the
/// surface; cosine-weighted sampling.
std::shared_ptr<Bsdf> make_diffuse_bsdf(std::shared_ptr<const Texture> reflectance);

/// Mitsuba's `twosided`: `front` seen from the front; from the back, `back` (the same BSDF when
/// one was nested) with both directions mirrored to the front. Pointers must outlive the result.
std::shared_ptr<Bsdf> make_twosided_bsdf(const Bsdf* front, const Bsdf* back);

}  // namespace tessera
