// Diffuse area light on a shape, constructible without a scene file (tests, tools).
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/render/light.h"
#include "tessera/render/shape.h"

#include <memory>

namespace tessera {

/// Constant radiance `radiance` leaving the side of `shape` its geometric normal points to (none
/// from the back). sample_li samples the shape uniformly by area. `shape` must outlive the light.
/// The caller attaches it (shape.light = result.get()).
std::unique_ptr<Light> make_area_light(const Shape& shape, Rgb radiance);

}  // namespace tessera
