// Mitsuba's `thinlens` sensor (perspective projection plus a circular thin lens).
//
// Camera space as in perspective_camera.cpp: the pinhole ray of a raster position has direction
//   (tan(fov_x/2) (1 - 2 sx), tan(fov_x/2) (1 - 2 sy) / aspect, 1),
// and meets the focus plane z = focus_distance at that direction times focus_distance. The lens
// point a = aperture_radius * concentric_disk(u_lens) lies in the z = 0 plane; the ray goes from a
// through the focus point (Mitsuba 0.6 and 3 sample_ray). A point at depth d off the focus plane f
// is thus spread over a disk of radius aperture_radius |d - f| / d on the focus plane, i.e.
// aperture_radius |d - f| / (d f) in units of the z = 1 image plane.
#include "tessera/core/check.h"
#include "tessera/core/sampling.h"
#include "tessera/render/camera.h"

#include <cmath>

namespace tessera {
namespace {

class ThinLensCamera final : public Camera {
 public:
  ThinLensCamera(const Transform& world_from_camera, float fov_x_degrees, int width, int height, float near_clip,
                 float far_clip, float aperture_radius, float focus_distance)
      : world_from_camera_(world_from_camera),
        near_(near_clip),
        far_(far_clip),
        aperture_(aperture_radius),
        focus_(focus_distance) {
    TESSERA_CHECK(width > 0 && height > 0);
    TESSERA_CHECK(fov_x_degrees > 0.f && fov_x_degrees < 180.f);
    TESSERA_CHECK(aperture_radius >= 0.f && focus_distance > 0.f);
    inv_width_ = 1.f / float(width);
    inv_height_ = 1.f / float(height);
    double aspect = double(width) / double(height);
    tan_half_x_ = float(std::tan(double(fov_x_degrees) * kPi / 360.0));
    tan_half_y_ = float(double(tan_half_x_) / aspect);
  }

  Ray generate_ray(Vec2 raster, Vec2 u_lens) const override {
    float sx = raster.x * inv_width_, sy = raster.y * inv_height_;
    Vec3 focus_p = Vec3(tan_half_x_ * (1.f - 2.f * sx), tan_half_y_ * (1.f - 2.f * sy), 1.f) * focus_;
    Vec2 lens = square_to_uniform_disk_concentric(u_lens) * aperture_;
    Vec3 aperture_p(lens.x, lens.y, 0.f);
    Vec3 d_cam = normalize(focus_p - aperture_p);
    Vec3 d_world = world_from_camera_.apply_vector(d_cam);
    // As in the perspective camera: clip distances stay in camera units under a uniform scale.
    float len = length(d_world);
    Ray ray;
    ray.o = world_from_camera_.apply_point(aperture_p);
    ray.d = d_world / len;
    float inv_z = 1.f / d_cam.z;
    ray.tmin = near_ * inv_z * len;
    ray.tmax = far_ * inv_z * len;
    return ray;
  }

 private:
  Transform world_from_camera_;
  float near_, far_, aperture_, focus_;
  float inv_width_, inv_height_;
  float tan_half_x_, tan_half_y_;
};

}  // namespace

std::unique_ptr<Camera> make_thinlens_camera(const Transform& world_from_camera, float fov_x_degrees,
                                             int film_width, int film_height, float near_clip, float far_clip,
                                             float aperture_radius, float focus_distance) {
  return std::make_unique<ThinLensCamera>(world_from_camera, fov_x_degrees, film_width, film_height, near_clip,
                                          far_clip, aperture_radius, focus_distance);
}

}  // namespace tessera
