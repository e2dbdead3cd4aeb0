// Camera, film and pixel-filter interfaces.
//
// Raster space: continuous pixel coordinates of the full film, (0,0) at the top-left corner of the
// top-left pixel, x to the right, y down; pixel (i,j) covers [i,i+1) x [j,j+1).
// Pixel filters are applied by filter importance sampling (the film position of a sample is drawn
// from the filter around the pixel centre), so each pixel's value depends on its own samples only.
#pragma once

#include "tessera/core/animated_transform.h"
#include "tessera/core/ray.h"
#include "tessera/core/rgb.h"
#include "tessera/core/transform.h"
#include "tessera/core/vec.h"

#include <memory>
#include <string>

namespace tessera {

class Filter {
 public:
  virtual ~Filter() = default;
  /// Offset from the pixel centre, in pixels, distributed proportionally to the filter.
  virtual Vec2 sample(Vec2 u) const = 0;
  virtual float radius() const = 0;
  virtual std::string name() const = 0;
  /// The filter's normalised kernel at `offset` from the pixel centre (in pixels): the density
  /// sample() draws offsets with, integrating to 1 over [-radius, radius]^2. A sample of radiance
  /// landing at raster point x counts in pixel (i, j) with weight eval(x - centre(i, j)) (light
  /// tracing splats through it, so it converges to the image of the film's filtered samples).
  virtual float eval(Vec2 offset) const = 0;
};

std::unique_ptr<Filter> make_box_filter(float radius = 0.5f);
std::unique_ptr<Filter> make_tent_filter(float radius = 1.f);
std::unique_ptr<Filter> make_gaussian_filter(float stddev = 0.5f, float radius = 2.f);

struct FilmSettings {
  int width = 768, height = 576;
  int crop_x = 0, crop_y = 0, crop_width = 0, crop_height = 0;  // crop_width==0: whole film
  bool ldr = false;            // ldrfilm: PNG gets gamma/exposure below
  float gamma = -1.f;          // ldrfilm gamma; -1 = sRGB curve
  float exposure = 0.f;        // ldrfilm exposure in stops
  std::shared_ptr<const Filter> filter;  // never null after load (Mitsuba default: gaussian)
  int crop_w() const { return crop_width > 0 ? crop_width : width; }
  int crop_h() const { return crop_height > 0 ? crop_height : height; }
};

/// A point on the camera's lens seen from a reference point (Camera::sample_wi).
struct CameraSampleWi {
  Vec3 p_lens;     // world: the point on the lens (the pinhole for a pinhole camera)
  Vec3 n;          // world: the camera's viewing direction (its +z), unit
  Vec3 wi;         // unit, world: from the reference point towards p_lens
  float dist = 0.f;  // from the reference point to p_lens
  Rgb we;          // importance the camera gives the ray p_lens -> reference point (We)
  float pdf = 0.f;   // density of p_lens per unit SOLID ANGLE at the reference point
  Vec2 raster;     // where that ray crosses the film (raster space, above)
};

class Camera {
 public:
  virtual ~Camera() = default;
  // Importance (light tracing and bidirectional methods), after pbrt-v4's PerspectiveCamera:
  // We(p, w) = 1 / (A * lens_area * cos^4 theta) for rays that land on the film, 0 elsewhere, A the
  // area of the whole film's image on the plane at distance 1 in front of the lens, theta the angle
  // of w to the viewing direction; so We integrates to 1 over the film (per unit lens area).
  /// Whether the methods below are implemented (perspective and thin lens cameras).
  virtual bool has_importance() const { return false; }
  /// We for the ray leaving the lens at ray.o along ray.d at time ray.time; where it crosses the film
  /// into `raster` when not null. Black when it misses the film or points backwards.
  virtual Rgb we(const Ray& ray, Vec2* raster) const { return {}; }
  /// Densities with which generating rays over the whole film (uniform raster position, uniform lens
  /// point) gives `ray`: pdf_pos per unit lens area (1 for a pinhole), pdf_dir per unit solid angle
  /// (1 / (A cos^3 theta) on the film, 0 off it).
  virtual void pdf_we(const Ray& ray, float& pdf_pos, float& pdf_dir) const {
    pdf_pos = 0.f;
    pdf_dir = 0.f;
  }
  /// Samples a point on the lens (from `u_lens`, as generate_ray does) that sees `ref_p` at `time`:
  /// false when ref_p is behind the camera, closer than the near clip, or off the film.
  virtual bool sample_wi(Vec3 ref_p, Vec2 u_lens, float time, CameraSampleWi& out) const { return false; }
  /// Ray through raster position `raster` (see above); `u_lens` for depth of field. Direction unit.
  virtual Ray generate_ray(Vec2 raster, Vec2 u_lens) const = 0;
  /// The ray at scene time `time` (motion blur); a camera that does not move just stamps the time.
  virtual Ray generate_ray_at(Vec2 raster, Vec2 u_lens, float time) const {
    Ray r = generate_ray(raster, u_lens);
    r.time = time;
    return r;
  }
};

/// Mitsuba's perspective sensor: looks down +z of `world_from_camera` with +y up, image x mirrored
/// as Mitsuba does (camera-space +x appears on the left of the image).
/// `fov_x_degrees` is the horizontal field of view after fovAxis resolution.
std::unique_ptr<Camera> make_perspective_camera(const Transform& world_from_camera, float fov_x_degrees,
                                                int film_width, int film_height, float near_clip,
                                                float far_clip);

/// Mitsuba's `thinlens` sensor: the perspective camera above with a thin lens of radius
/// `aperture_radius` in the camera's z = 0 plane, sampled with the concentric disk map from
/// `u_lens`; every ray of a raster position passes through the pinhole ray's point on the focus
/// plane z = focus_distance (camera space), so that plane is sharp. aperture_radius 0: a pinhole.
std::unique_ptr<Camera> make_thinlens_camera(const Transform& world_from_camera, float fov_x_degrees,
                                             int film_width, int film_height, float near_clip, float far_clip,
                                             float aperture_radius, float focus_distance);

/// Mitsuba's `orthographic` sensor: rays along camera +z from the z = 0 plane, camera-space
/// x in [-1, 1] across the film width and y in [-1/aspect, 1/aspect] (aspect = width / height)
/// across its height, x mirrored as in the perspective camera. The extent comes from the scale in
/// `world_from_camera`; the clip distances are along the (unit) world direction.
std::unique_ptr<Camera> make_orthographic_camera(const Transform& world_from_camera, int film_width,
                                                 int film_height, float near_clip, float far_clip);

/// A camera moving with `world_from_camera` (its to_world animation): `inner` was built with the
/// transform at shutter open, `world_from_camera_open`; rays at time t are moved by
/// world_from_camera(t) * inverse(world_from_camera_open).
std::unique_ptr<Camera> make_animated_camera(std::unique_ptr<Camera> inner, const Transform& world_from_camera_open,
                                             AnimatedTransform world_from_camera);

}  // namespace tessera
