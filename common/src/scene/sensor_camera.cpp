// Sensor type dispatch: which camera a <sensor> becomes, and the parameters only some types read.
// sensor_builder.cpp reads what they share (field of view, clip distances, to_world, film).
#include "tessera/scene/load_context.h"

#include "scene/builder_internal.h"

#include <cmath>

namespace tessera::detail {

bool is_supported_sensor(const std::string& type) {
  return type == "perspective" || type == "thinlens" || type == "orthographic";
}

bool sensor_has_fov(const std::string& type) { return type != "orthographic"; }

std::unique_ptr<Camera> make_sensor_camera(LoadContext& ctx, const SceneNode& sensor, const Transform& to_world,
                                           float fov_x, const FilmSettings& film, float near_clip, float far_clip) {
  if (sensor.type == "orthographic")
    return make_orthographic_camera(to_world, film.width, film.height, near_clip, far_clip);
  if (sensor.type == "thinlens") {
    // Mitsuba 0.6 and 3 require the aperture radius; the focus distance defaults to far_clip.
    const Property* ap = sensor.find("aperture_radius");
    if (!ap) throw SceneError(sensor.loc, sensor.describe() + " needs 'aperture_radius'");
    float aperture = sensor.get_float("aperture_radius", 0.f);
    if (!(aperture >= 0.f) || !std::isfinite(aperture))
      throw SceneError(ap->loc, "aperture_radius must be a finite number >= 0");
    const Property* fp = sensor.find("focus_distance");
    float focus = sensor.get_float("focus_distance", far_clip);
    if (!(focus > 0.f) || !std::isfinite(focus))
      throw SceneError(fp ? fp->loc : sensor.loc, "focus_distance must be a finite positive number");
    if (aperture == 0.f)
      ctx.note(ap->loc, sensor.describe() + ": aperture_radius 0 renders as a pinhole camera");
    return make_thinlens_camera(to_world, fov_x, film.width, film.height, near_clip, far_clip, aperture, focus);
  }
  // `perspective`, and the documented fallback for unsupported sensor types.
  return make_perspective_camera(to_world, fov_x, film.width, film.height, near_clip, far_clip);
}

}  // namespace tessera::detail
