// Mitsuba's `directional` emitter: light from an infinitely distant source arriving along one
// direction (a delta in direction), constructible without a scene file (tests, sunsky).
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/render/light.h"

#include <memory>

namespace tessera {

/// `direction`: the way the light travels (world space, normalised here); `irradiance`: W m^-2 on a
/// surface facing the light. sample_li gives wi = -direction, li = irradiance, pdf 1, delta, an
/// infinite distance; power() = luminance(irradiance) * pi R^2 with R the radius of the scene's
/// bounding sphere (1 before preprocess), the power crossing the scene's cross-section.
std::unique_ptr<Light> make_directional_light(Vec3 direction, Rgb irradiance);

}  // namespace tessera
