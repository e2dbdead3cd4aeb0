// A camera whose to_world is animated (<animation> in the sensor): the wrapped camera is built at
// the shutter-open transform W0, and each ray it makes is carried by W(t) W0^-1 to the ray time.
// For rigid motion this is exactly the camera at W(t); a scale that changes over the shutter (an
// orthographic camera zooming) moves the ray origins as the scale does and re-normalises the
// direction, keeping the clip range on the same points.
#include "tessera/core/animated_transform.h"
#include "tessera/render/camera.h"

#include <utility>

namespace tessera {
namespace {

class AnimatedCamera final : public Camera {
 public:
  AnimatedCamera(std::unique_ptr<Camera> inner, const Transform& world_from_camera_open,
                 AnimatedTransform world_from_camera)
      : inner_(std::move(inner)), open_inverse_(world_from_camera_open.inverse()),
        world_from_camera_(std::move(world_from_camera)) {}

  Ray generate_ray(Vec2 raster, Vec2 u_lens) const override { return inner_->generate_ray(raster, u_lens); }

  Ray generate_ray_at(Vec2 raster, Vec2 u_lens, float time) const override {
    Ray r = inner_->generate_ray_at(raster, u_lens, time);
    const Transform motion = world_from_camera_.at(time) * open_inverse_;
    const Vec3 d = motion.apply_vector(r.d);
    const float len = length(d);
    if (!(len > 0.f)) return r;  // a degenerate keyframe: keep the shutter-open ray
    r.o = motion.apply_point(r.o);
    r.d = d * (1.f / len);
    r.tmin *= len;
    r.tmax *= len;
    return r;
  }

 private:
  std::unique_ptr<Camera> inner_;
  Transform open_inverse_;
  AnimatedTransform world_from_camera_;
};

}  // namespace

std::unique_ptr<Camera> make_animated_camera(std::unique_ptr<Camera> inner, const Transform& world_from_camera_open,
                                             AnimatedTransform world_from_camera) {
  return std::make_unique<AnimatedCamera>(std::move(inner), world_from_camera_open, std::move(world_from_camera));
}

}  // namespace tessera
