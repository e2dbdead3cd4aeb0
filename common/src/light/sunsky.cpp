// The `sunsky`, `sky` and `sun` factories (Mitsuba 0.5/0.6 parameters; data/sunsky SPEC §2, §6).
// A sunsky with sunRadiusScale = 0 is two lights: the factory adds the directional sun to
// ctx.scene().lights itself and returns the sky map (the LightFactory contract, load_context.h).
#include "tessera/light/sunsky.h"

#include "tessera/light/directional.h"
#include "tessera/light/envmap.h"
#include "tessera/light/sunsky/hosek_sky.h"
#include "tessera/light/sunsky/sunsky_bake.h"
#include "tessera/light/sunsky/sun_spectrum.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>

namespace tessera {

namespace {
constexpr double kPiD = 3.14159265358979323846;
}  // namespace

Vec3 sunsky_sun_direction_world(const SunskySettings& s) {
  const Vec3 local = sunsky_direction(std::min(s.stretch * s.sun.theta, kPiD), s.sun.phi);
  return normalize(s.to_world.apply_vector(local));
}

Rgb sunsky_sun_radiance(const SunskySettings& s) { return sun_radiance(s.turbidity, s.sun.theta).rgb * s.sun_scale; }

Rgb sunsky_sun_irradiance(const SunskySettings& s) { return sunsky_sun_radiance(s) * float(sun_solid_angle()); }

SunskyLights make_sunsky_lights(const SunskySettings& s) {
  SunskyLights out;
  const bool sun_in_map = s.with_sun && s.sun_radius_scale > 0.0;
  if (s.with_sun && !sun_in_map)
    out.directional = make_directional_light(-sunsky_sun_direction_world(s), sunsky_sun_irradiance(s));
  if (!s.with_sky && !sun_in_map) return out;

  const int width = s.resolution, height = sunsky_map_height(s.resolution);
  Image map(width, height, 3);
  if (s.with_sky)
    map = bake_sky_map(HosekSky(s.turbidity, s.albedo, s.sun.theta), s.sun.phi, s.stretch, s.sky_scale, width,
                       height);
  if (sun_in_map) {
    const Vec3 local = sunsky_direction(std::min(s.stretch * s.sun.theta, kPiD), s.sun.phi);
    splat_sun(map, local, kSunHalfAngle * s.sun_radius_scale, sunsky_sun_irradiance(s), s.resolution);
  }
  out.map = std::make_unique<EnvmapLight>(map, 1.f, s.to_world);
  return out;
}

namespace {

FileLoc loc_of(const SceneNode& node, const char* name) {
  const Property* p = node.peek(name);
  return p ? p->loc : node.loc;
}

double read_in_range(const SceneNode& node, const char* name, double def, double lo, double hi) {
  const double v = node.get_float(name, float(def));
  if (!(v >= lo && v <= hi))
    throw SceneError(loc_of(node, name), node.describe() + ": '" + name + "' must lie in [" + std::to_string(lo) +
                                             ", " + std::to_string(hi) + "], got " + std::to_string(v));
  return v;
}

float read_scale(const SceneNode& node, const char* name, float def) {
  const float v = node.get_float(name, def);
  if (!std::isfinite(v) || v < 0.f)
    throw SceneError(loc_of(node, name), node.describe() + ": '" + name + "' must be finite and non-negative");
  return v;
}

// sunDirection (world space, towards the sun), or else date, time and place.
SunAngles read_sun_position(const SceneNode& node, const Transform& to_world) {
  static const char* const kTimeAndPlace[] = {"year", "month", "day", "hour", "minute", "second",
                                              "latitude", "longitude", "timezone"};
  SunAngles sun;
  if (node.has("sun_direction")) {
    for (const char* p : kTimeAndPlace)
      if (node.has(p))
        throw SceneError(loc_of(node, p), node.describe() + ": give either 'sunDirection' or a date, time and "
                                          "location ('" + std::string(p) + "'), not both");
    const Vec3 v = node.get_vector("sun_direction", Vec3(0.f, 1.f, 0.f));
    const Vec3 local = to_world.inverse().apply_vector(v);
    if (!(length(local) > 0.f) || !std::isfinite(length(local)))
      throw SceneError(loc_of(node, "sun_direction"), node.describe() + ": 'sunDirection' must be a non-zero vector");
    sun = sun_angles_from_direction(local);
  } else {
    SunTimeAndPlace w;
    w.year = int(node.get_int("year", w.year));
    w.month = int(node.get_int("month", w.month));
    w.day = int(node.get_int("day", w.day));
    w.hour = node.get_float("hour", float(w.hour));
    w.minute = node.get_float("minute", float(w.minute));
    w.second = node.get_float("second", float(w.second));
    w.latitude = node.get_float("latitude", float(w.latitude));
    w.longitude = node.get_float("longitude", float(w.longitude));
    w.timezone = node.get_float("timezone", float(w.timezone));
    sun = solar_position(w);
  }
  if (!(sun.theta <= 0.5 * kPiD))
    throw SceneError(node.loc, node.describe() + ": the sun is below the horizon (elevation " +
                                   std::to_string(90.0 - sun.theta * 180.0 / kPiD) +
                                   " deg); the sun and sky models do not cover night");
  return sun;
}

enum class Part { SunSky, Sky, Sun };

SunskySettings read_settings(const SceneNode& node, Part part) {
  SunskySettings s;
  s.with_sky = part != Part::Sun;
  s.with_sun = part != Part::Sky;
  s.turbidity = read_in_range(node, "turbidity", s.turbidity, 1.0, 10.0);
  if (s.with_sky) {
    s.albedo = node.get_color("albedo", s.albedo);
    for (int c = 0; c < 3; ++c)
      if (!(s.albedo[c] >= 0.f && s.albedo[c] <= 1.f))
        throw SceneError(loc_of(node, "albedo"), node.describe() + ": 'albedo' must lie in [0, 1] per channel");
    s.stretch = read_in_range(node, "stretch", s.stretch, 1.0, 2.0);
  }
  const int64_t res = node.get_int("resolution", s.resolution);
  if (res < 4 || res > 65536)
    throw SceneError(loc_of(node, "resolution"), node.describe() + ": 'resolution' must lie in [4, 65536]");
  s.resolution = int(res);
  const float scale = read_scale(node, "scale", 1.f);
  if (part == Part::SunSky) {
    s.sun_scale = read_scale(node, "sun_scale", scale);
    s.sky_scale = read_scale(node, "sky_scale", scale);
  } else {
    s.sun_scale = s.sky_scale = scale;
  }
  if (s.with_sun) s.sun_radius_scale = read_in_range(node, "sun_radius_scale", s.sun_radius_scale, 0.0, kPiD / kSunHalfAngle);
  s.to_world = node.get_transform("to_world", Transform());
  s.sun = read_sun_position(node, s.to_world);
  return s;
}

std::unique_ptr<Light> make(const SceneNode& node, LoadContext& ctx, Part part) {
  SunskyLights lights = make_sunsky_lights(read_settings(node, part));
  if (!lights.map) return std::move(lights.directional);
  if (lights.directional) ctx.scene().lights.push_back(std::move(lights.directional));
  return std::move(lights.map);
}

}  // namespace

std::unique_ptr<Light> make_sunsky(const SceneNode& node, LoadContext& ctx) { return make(node, ctx, Part::SunSky); }
std::unique_ptr<Light> make_sky(const SceneNode& node, LoadContext& ctx) { return make(node, ctx, Part::Sky); }
std::unique_ptr<Light> make_sun(const SceneNode& node, LoadContext& ctx) { return make(node, ctx, Part::Sun); }

}  // namespace tessera
