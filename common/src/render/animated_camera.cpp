// A camera whose to_world is animated (<animation> in the sensor): the wrapped camera is built at
// the shutter-open transform W0, and each ray it makes is carried by W(t) W0^-1 to the ray time.
// For rigid motion this is exactly the camera at W(t); a scale that changes over the shutter (an
// orthographic camera zooming) moves the ray origins as the scale does and re-normalises the
// direction, keeping the clip range on the same points.
//
// Importance is answered by the wrapped camera in its shutter-open frame: rays and reference points
// are carried back by the inverse motion at their time, lens points forward. We and the pdfs pass
// through unchanged, which is exact for rigid motion (angles and areas kept); a perspective camera
// whose to_world scale animates would need its lens area rescaled, and is not supported here.
#include "tessera/core/animated_transform.h"
// camera.h uses Rgb without including rgb.h (reported to the lead); included first until fixed.
#include "tessera/core/rgb.h"
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

  bool has_importance() const override { return inner_->has_importance(); }

  Rgb we(const Ray& ray, Vec2* raster) const override { return inner_->we(to_open(ray), raster); }

  void pdf_we(const Ray& ray, float& pdf_pos, float& pdf_dir) const override {
    inner_->pdf_we(to_open(ray), pdf_pos, pdf_dir);
  }

  bool sample_wi(Vec3 ref_p, Vec2 u_lens, float time, CameraSampleWi& out) const override {
    const Transform motion = motion_at(time);
    if (!inner_->sample_wi(motion.inverse().apply_point(ref_p), u_lens, time, out)) return false;
    out.p_lens = motion.apply_point(out.p_lens);
    out.n = normalize(motion.apply_vector(out.n));
    // Recomputed in world space rather than rotated, so wi and dist agree with p_lens exactly.
    const Vec3 to_lens = out.p_lens - ref_p;
    out.dist = length(to_lens);
    if (!(out.dist > 0.f)) return false;
    out.wi = to_lens / out.dist;
    return true;
  }

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
  Transform motion_at(float time) const { return world_from_camera_.at(time) * open_inverse_; }

  // `ray` carried back to the shutter-open frame the wrapped camera was built in.
  Ray to_open(const Ray& ray) const {
    const Transform back = motion_at(ray.time).inverse();
    Ray r = ray;
    r.o = back.apply_point(ray.o);
    r.d = normalize(back.apply_vector(ray.d));
    return r;
  }

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
