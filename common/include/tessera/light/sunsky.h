// Mitsuba 0.5/0.6's `sunsky`, `sky` and `sun` emitters, constructible without a scene file.
//
// Each becomes a latitude-longitude EnvmapLight baked at load time (light/sunsky/sunsky_bake.h):
// the Hosek-Wilkie sky (light/sunsky/hosek_sky.h) and/or the sun disk (light/sunsky/sun_spectrum.h)
// splatted into the same map. With sun_radius_scale = 0 the sun is a separate directional light of
// the same irradiance instead. Units: W m^-2 sr^-1 nm^-1 (Mitsuba's), times sky_scale / sun_scale.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/transform.h"
#include "tessera/light/sunsky/solar_position.h"
#include "tessera/render/light.h"

#include <memory>

namespace tessera {

struct SunskySettings {
  double turbidity = 3;          // [1, 10]
  Rgb albedo = Rgb(0.2f);        // ground albedo per channel, [0, 1] (sky only)
  double stretch = 1;            // [1, 2] (sky, and where the disk sits)
  int resolution = 512;          // map width; height = resolution / 2 + 1 rows
  float sky_scale = 1, sun_scale = 1;
  double sun_radius_scale = 1;   // >= 0; 0: the sun is a directional light
  SunAngles sun;                 // light-space sun position (above the horizon)
  Transform to_world;            // light space -> world (a rotation)
  bool with_sky = true, with_sun = true;
};

struct SunskyLights {
  std::unique_ptr<Light> map;          // EnvmapLight; null for a sun-only directional
  std::unique_ptr<Light> directional;  // the sun when sun_radius_scale = 0 (and with_sun)
};

SunskyLights make_sunsky_lights(const SunskySettings& s);

/// World direction towards the centre of the sun disk (at zenith angle stretch * theta_s).
Vec3 sunsky_sun_direction_world(const SunskySettings& s);
/// Disk radiance times sun_scale, and the irradiance it gives at normal incidence (times the disk's
/// solid angle, whatever sun_radius_scale).
Rgb sunsky_sun_radiance(const SunskySettings& s);
Rgb sunsky_sun_irradiance(const SunskySettings& s);

}  // namespace tessera
