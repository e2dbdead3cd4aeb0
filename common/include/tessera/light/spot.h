// Spot light (Mitsuba 0.6 / 3 `spot`), constructible without a scene file (tests, tools).
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/transform.h"
#include "tessera/render/light.h"
#include "tessera/render/texture.h"

#include <memory>

namespace tessera {

/// A point light at world_from_light(0) shining down light-space +z. Radiant intensity along a
/// light-space direction at angle theta from +z is `intensity` * falloff(theta) [* texture(uv)]:
///   falloff = 1 for theta <= beam_width, (cutoff - theta) / (cutoff - beam_width) up to the
///   cutoff (linear in the ANGLE, as Mitsuba 0.6 and 3 do), 0 beyond it.
/// `texture` (optional, may be null) is projected through the cone as Mitsuba does:
///   uv = 0.5 + 0.5 (x, y) / (z tan(cutoff)), so the cutoff circle touches the unit square's edges.
/// Angles in degrees: 0 < cutoff <= 180, 0 <= beam_width <= cutoff; with a texture, cutoff < 90.
std::unique_ptr<Light> make_spot_light(const Transform& world_from_light, Rgb intensity, float cutoff_degrees,
                                       float beam_width_degrees, std::shared_ptr<const Texture> texture = nullptr);

/// Integral over the sphere of the falloff profile above (steradians):
///   2 pi (1 + (sin beam - sin cutoff) / (cutoff - beam)), or 2 pi (1 - cos cutoff) without a ramp.
double spot_profile_solid_angle(double cutoff_radians, double beam_width_radians);

}  // namespace tessera
