// Mitsuba 0.6's `blendbsdf`, constructible without a scene file (tests, tools).
#pragma once

#include "tessera/render/bsdf.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// (1 - w) * first + w * second, w = weight->eval_1(si) clamped to [0, 1] (Mitsuba: the channel
/// average). Sampling picks `second` with probability w, reusing u1 for the component's own lobe
/// choice. Pointers must outlive the result.
std::shared_ptr<Bsdf> make_blend_bsdf(std::shared_ptr<const Texture> weight, const Bsdf* first, const Bsdf* second);

}  // namespace tessera
