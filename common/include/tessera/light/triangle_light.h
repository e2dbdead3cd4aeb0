// One triangle of an emissive mesh as a light of its own. Light selection needs emitters small
// enough to have a meaningful position and orientation (a light hierarchy cannot tell a lamp from
// a whole ceiling of lamps otherwise), so Scene::finalize replaces a mesh's `area` emitter by one
// of these per triangle (Light::make_primitive_lights) and the shape maps hits to them
// (Shape::prim_lights), so that the light MIS sees at a hit is the one that was sampled.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/render/light.h"
#include "tessera/render/shape.h"

#include <memory>

namespace tessera {

/// Constant radiance leaving the front (geometric-normal side) of triangle `tri` of `mesh`,
/// sampled uniformly by area. `mesh` must outlive the light.
std::unique_ptr<Light> make_triangle_light(const TriangleMeshShape& mesh, uint32_t tri, Rgb radiance);

}  // namespace tessera
