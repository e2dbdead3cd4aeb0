// Mitsuba's `perspective` sensor (pinhole) and `thinlens` sensor (the same projection through a
// circular thin lens): one class, the pinhole being the lens of radius 0.
//
// Mitsuba builds camera_to_sample = scale(-0.5, -0.5 aspect, 1) * translate(-1, -1/aspect, 0) *
// perspective(fov_x, near, far), sample space being [0,1]^2 over the film. Inverting it for a point
// on the image plane z = 1 gives the camera-space direction used below:
//   x = tan(fov_x/2) * (1 - 2 sx),  y = tan(fov_x/2) * (1 - 2 sy) / aspect,  z = 1
// so camera +x lands on the LEFT of the image and +y at the top. The ray starts on the near plane
// (tmin = near / d.z for unit d), as Mitsuba's sample_ray does.
//
// Thin lens: the pinhole ray meets the focus plane z = focus_distance at its direction times
// focus_distance. The lens point a = aperture_radius * concentric_disk(u_lens) lies in the z = 0
// plane; the ray goes from a through that focus point (Mitsuba 0.6 and 3 sample_ray). A point at
// depth d off the focus plane f is thus spread over a disk of radius aperture_radius |d - f| / d on
// the focus plane, i.e. aperture_radius |d - f| / (d f) in units of the z = 1 image plane.
#include "tessera/render/camera.h"

#include "tessera/core/check.h"
#include "tessera/core/sampling.h"

#include <cmath>

namespace tessera {
namespace {

class PerspectiveCamera final : public Camera {
 public:
  PerspectiveCamera(const Transform& world_from_camera, float fov_x_degrees, int width, int height,
                    float near_clip, float far_clip, float aperture_radius = 0.f, float focus_distance = 1.f)
      : world_from_camera_(world_from_camera), near_(near_clip), far_(far_clip), aperture_(aperture_radius),
        focus_(focus_distance) {
    TESSERA_CHECK(width > 0 && height > 0);
    TESSERA_CHECK(fov_x_degrees > 0.f && fov_x_degrees < 180.f);
    TESSERA_CHECK(aperture_radius >= 0.f && focus_distance > 0.f);
    inv_width_ = 1.f / float(width);
    inv_height_ = 1.f / float(height);
    double aspect = double(width) / double(height);
    tan_half_x_ = float(std::tan(double(fov_x_degrees) * kPi / 360.0));
    tan_half_y_ = float(double(tan_half_x_) / aspect);
    origin_ = world_from_camera_.apply_point(Vec3(0.f));
  }

  Ray generate_ray(Vec2 raster, Vec2 u_lens) const override {
    float sx = raster.x * inv_width_, sy = raster.y * inv_height_;
    const Vec3 pinhole(tan_half_x_ * (1.f - 2.f * sx), tan_half_y_ * (1.f - 2.f * sy), 1.f);
    Vec3 d_cam, o_world = origin_;
    if (aperture_ > 0.f) {
      const Vec2 lens = square_to_uniform_disk_concentric(u_lens) * aperture_;
      const Vec3 aperture_p(lens.x, lens.y, 0.f);
      d_cam = normalize(pinhole * focus_ - aperture_p);
      o_world = world_from_camera_.apply_point(aperture_p);
    } else {
      d_cam = normalize(pinhole);
    }
    Vec3 d_world = world_from_camera_.apply_vector(d_cam);
    // A to_world with (unsupported but harmless) uniform scale would stretch t: keep distances in
    // camera units by rescaling the clip distances along the normalised world direction.
    float len = length(d_world);
    Ray ray;
    ray.o = o_world;
    ray.d = d_world / len;
    float inv_z = 1.f / d_cam.z;
    ray.tmin = near_ * inv_z * len;
    ray.tmax = far_ * inv_z * len;
    return ray;
  }

 private:
  Transform world_from_camera_;
  Vec3 origin_;
  float near_, far_, aperture_, focus_;
  float inv_width_, inv_height_;
  float tan_half_x_, tan_half_y_;
};

}  // namespace

std::unique_ptr<Camera> make_perspective_camera(const Transform& world_from_camera, float fov_x_degrees,
                                                int film_width, int film_height, float near_clip,
                                                float far_clip) {
  return std::make_unique<PerspectiveCamera>(world_from_camera, fov_x_degrees, film_width, film_height,
                                             near_clip, far_clip);
}

std::unique_ptr<Camera> make_thinlens_camera(const Transform& world_from_camera, float fov_x_degrees,
                                             int film_width, int film_height, float near_clip, float far_clip,
                                             float aperture_radius, float focus_distance) {
  return std::make_unique<PerspectiveCamera>(world_from_camera, fov_x_degrees, film_width, film_height, near_clip,
                                             far_clip, aperture_radius, focus_distance);
}

}  // namespace tessera
