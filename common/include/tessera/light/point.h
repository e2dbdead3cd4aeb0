// Isotropic point light, constructible without a scene file (tests, tools).
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/render/light.h"

#include <memory>

namespace tessera {

/// Radiant intensity `intensity` (W/sr) at `position`: li = I / d^2, power 4 pi I.
std::unique_ptr<Light> make_point_light(Vec3 position, Rgb intensity);

}  // namespace tessera
