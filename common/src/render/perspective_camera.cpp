// Mitsuba's `perspective` sensor (pinhole).
//
// Mitsuba builds camera_to_sample = scale(-0.5, -0.5 aspect, 1) * translate(-1, -1/aspect, 0) *
// perspective(fov_x, near, far), sample space being [0,1]^2 over the film. Inverting it for a point
// on the image plane z = 1 gives the camera-space direction used below:
//   x = tan(fov_x/2) * (1 - 2 sx),  y = tan(fov_x/2) * (1 - 2 sy) / aspect,  z = 1
// so camera +x lands on the LEFT of the image and +y at the top. The ray starts on the near plane
// (tmin = near / d.z for unit d), as Mitsuba's sample_ray does.
#include "tessera/render/camera.h"

#include "tessera/core/check.h"

#include <cmath>

namespace tessera {
namespace {

class PerspectiveCamera final : public Camera {
 public:
  PerspectiveCamera(const Transform& world_from_camera, float fov_x_degrees, int width, int height,
                    float near_clip, float far_clip)
      : world_from_camera_(world_from_camera), near_(near_clip), far_(far_clip) {
    TESSERA_CHECK(width > 0 && height > 0);
    TESSERA_CHECK(fov_x_degrees > 0.f && fov_x_degrees < 180.f);
    inv_width_ = 1.f / float(width);
    inv_height_ = 1.f / float(height);
    double aspect = double(width) / double(height);
    tan_half_x_ = float(std::tan(double(fov_x_degrees) * kPi / 360.0));
    tan_half_y_ = float(double(tan_half_x_) / aspect);
    origin_ = world_from_camera_.apply_point(Vec3(0.f));
  }

  Ray generate_ray(Vec2 raster, Vec2 /*u_lens*/) const override {
    float sx = raster.x * inv_width_, sy = raster.y * inv_height_;
    Vec3 d_cam = normalize(Vec3(tan_half_x_ * (1.f - 2.f * sx), tan_half_y_ * (1.f - 2.f * sy), 1.f));
    Vec3 d_world = world_from_camera_.apply_vector(d_cam);
    // A to_world with (unsupported but harmless) uniform scale would stretch t: keep distances in
    // camera units by rescaling the clip distances along the normalised world direction.
    float len = length(d_world);
    Ray ray;
    ray.o = origin_;
    ray.d = d_world / len;
    float inv_z = 1.f / d_cam.z;
    ray.tmin = near_ * inv_z * len;
    ray.tmax = far_ * inv_z * len;
    return ray;
  }

 private:
  Transform world_from_camera_;
  Vec3 origin_;
  float near_, far_;
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

}  // namespace tessera
