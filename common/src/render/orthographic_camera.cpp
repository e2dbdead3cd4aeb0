// Mitsuba's `orthographic` sensor.
//
// Mitsuba 0.6 builds camera_to_sample = scale(-0.5, -0.5 aspect, 1) * translate(-1, -1/aspect, 0) *
// orthographic(near, far); inverted, sample (sx, sy) comes from the camera-space point
//   x = 1 - 2 sx,  y = (1 - 2 sy) / aspect
// on the z = 0 plane, so [-1, 1] spans the film width (camera +x on the LEFT, as for the
// perspective camera) and the height follows the aspect ratio. The ray leaves that point, moved by
// to_world (whose scale sets the extent), along the normalised world image of +z, with
// tmin = near_clip and tmax = far_clip measured along it (Mitsuba 0.6; Mitsuba 3 starts the ray at
// z = near_clip in camera space, the same unless to_world scales z).
#include "tessera/core/check.h"
// camera.h uses Rgb without including rgb.h (reported to the lead); included first until fixed.
#include "tessera/core/rgb.h"
#include "tessera/render/camera.h"

namespace tessera {
namespace {

class OrthographicCamera final : public Camera {
 public:
  OrthographicCamera(const Transform& world_from_camera, int width, int height, float near_clip, float far_clip)
      : world_from_camera_(world_from_camera), near_(near_clip), far_(far_clip) {
    TESSERA_CHECK(width > 0 && height > 0);
    inv_width_ = 1.f / float(width);
    inv_height_ = 1.f / float(height);
    inv_aspect_ = float(double(height) / double(width));
    d_ = normalize(world_from_camera_.apply_vector(Vec3(0.f, 0.f, 1.f)));
  }

  Ray generate_ray(Vec2 raster, Vec2 /*u_lens*/) const override {
    float sx = raster.x * inv_width_, sy = raster.y * inv_height_;
    Ray ray;
    ray.o = world_from_camera_.apply_point(Vec3(1.f - 2.f * sx, (1.f - 2.f * sy) * inv_aspect_, 0.f));
    ray.d = d_;
    ray.tmin = near_;
    ray.tmax = far_;
    return ray;
  }

 private:
  Transform world_from_camera_;
  Vec3 d_;
  float near_, far_;
  float inv_width_, inv_height_, inv_aspect_;
};

}  // namespace

std::unique_ptr<Camera> make_orthographic_camera(const Transform& world_from_camera, int film_width,
                                                 int film_height, float near_clip, float far_clip) {
  return std::make_unique<OrthographicCamera>(world_from_camera, film_width, film_height, near_clip, far_clip);
}

}  // namespace tessera
