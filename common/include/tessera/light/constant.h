// Mitsuba's `constant` emitter: the same radiance from every direction, sampled uniformly over the
// sphere (pdf 1 / (4 pi)), as Mitsuba 3 does.
#pragma once

#include "tessera/render/light.h"

namespace tessera {

class ConstantLight final : public Light {
 public:
  explicit ConstantLight(Rgb radiance) : radiance_(radiance) {}

  void preprocess(const Bounds3& scene_bounds) override;
  bool sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const override;
  Rgb le_env(Vec3 d) const override { return radiance_; }
  float pdf_env(Vec3 d) const override { return kInv4Pi; }
  /// Uniform directions over the sphere, from the scene's disk (Light::sample_le).
  bool sample_le(Vec2 u_pos, Vec2 u_dir, LightEmission& out) const override;
  void pdf_le(Vec3 p, Vec3 n, Vec3 dir, float& pdf_pos, float& pdf_dir) const override;
  bool is_infinite() const override { return true; }
  /// 4 pi * pi R^2 * luminance: radiance L from every direction through a disk of the scene's
  /// cross-section (R: bounding-sphere radius, 1 before preprocess), as pbrt-v4's uniform
  /// infinite light estimates it.
  float power() const override;

 private:
  Rgb radiance_;
  Vec3 center_;
  float radius_ = 1.f;
};

}  // namespace tessera
