// Mitsuba's `mask` (alpha transparency), constructible without a scene file (tests, tools).
#pragma once

#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// `nested` seen where the surface is opaque. eval/pdf/sample are the nested BSDF's, unscaled:
/// the integrator applies opacity() itself (see Bsdf::opacity), so that rays and shadow rays pass
/// through the transparent part with no extra path vertex. Coloured opacity is reduced to its
/// luminance: one scalar is what a stochastic pass-through can honour exactly. As in Mitsuba 0.6
/// and 3, an RGBA bitmap contributes its RGB; a scene takes the alpha with the bitmap's
/// `channel` "a". `nested` must outlive the result.
std::shared_ptr<Bsdf> make_mask_bsdf(const Bsdf* nested, std::shared_ptr<const Texture> opacity);

}  // namespace tessera
