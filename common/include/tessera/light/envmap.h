// Mitsuba's `envmap` emitter: an infinitely distant latitude-longitude radiance map.
//
// Orientation (verified against Mitsuba 3's src/emitters/envmap.cpp, the renderer of the shared
// references; Mitsuba 0.6 uses the same direction <-> (u, v) formulas): in light space +y is up,
//   u = atan2(d.x, -d.z) / (2 pi)  (wrapped to [0,1)),   v = acos(d.y) / pi,
//   d(u, v) = (sin(2 pi u) sin(pi v), cos(pi v), -cos(2 pi u) sin(pi v)),
// so the top row is the +y pole, the left edge looks down -z, u = 1/4 looks along +x and the
// image centre along +z. World directions are `world_from_light` (Mitsuba's to_world) applied to
// them. Lookup is bilinear with Mitsuba 3's texel placement: column x sits at u = (x + 0.5) / W
// and wraps around; row y sits at v = y / (H - 1), so the first and last rows lie on the poles.
// (Mitsuba 0.6 put row centres at (y + 0.5) / H; the two differ by a fraction of a texel.)
//
// Sampling: the (W) x (H - 1) cells between texel centres form a piecewise-constant Distribution2D
// with weight = mean corner luminance x solid angle of the cell; inside a cell, directions are
// uniform in solid angle (uniform in phi and in cos theta). pdf_env() is exactly that density, so
// it is positive wherever the bilinear radiance is, and light-sampling weights stay bounded near
// the poles. Mitsuba 3 instead warps with a bilinear density over the texel grid; the expected
// image is the same, only the noise differs.
#pragma once

#include "tessera/core/distribution.h"
#include "tessera/core/transform.h"
#include "tessera/image/image.h"
#include "tessera/render/light.h"

#include <vector>

namespace tessera {

/// Light-space direction -> (u, v) in [0,1)x[0,1] (conventions above).
Vec2 envmap_direction_to_uv(Vec3 d);
/// (u, v) -> unit light-space direction.
Vec3 envmap_uv_to_direction(Vec2 uv);

class EnvmapLight final : public Light {
 public:
  /// `radiance`: linear, at least 2x3 texels (alpha ignored). `world_from_light` should be a
  /// rotation (possibly with uniform scale or a mirror): directions are re-normalised, but a shear or
  /// non-uniform scale would make pdf_env() miss the Jacobian of the distortion.
  EnvmapLight(const Image& radiance, float scale, const Transform& world_from_light);

  void preprocess(const Bounds3& scene_bounds) override;
  bool sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const override;
  Rgb deferred_li(const LightSample& s) const override { return lookup(s.li_uv); }
  Rgb le_env(Vec3 d) const override;
  float pdf_env(Vec3 d) const override;
  /// Directions from the importance distribution (reversed: the way the light travels), from the
  /// scene's disk; pdf_dir(dir) = pdf_env(-dir), le = le_env(-dir) (Light::sample_le).
  bool sample_le(Vec2 u_pos, Vec2 u_dir, LightEmission& out) const override;
  void pdf_le(Vec3 p, Vec3 n, Vec3 dir, float& pdf_pos, float& pdf_dir) const override;
  bool is_infinite() const override { return true; }
  /// Texels, row tables and the sampling distribution.
  size_t memory_bytes() const override {
    return texels_.size() * sizeof(Rgb) + row_cos_.size() * sizeof(double) + inv_cell_solid_angle_.size() * sizeof(float) +
           distribution_.memory_bytes();
  }
  /// pi R^2 * integral over the sphere of the luminance (R: scene bounding-sphere radius, 1 before
  /// preprocess): the power that would cross a disk of the scene's cross-section.
  float power() const override;

  int width() const { return width_; }
  int height() const { return height_; }
  /// Bilinear radiance (times scale) at light-space (u, v).
  Rgb lookup(Vec2 uv) const;
  Vec3 to_light(Vec3 d_world) const;
  Vec3 to_world(Vec3 d_light) const;

 private:
  Rgb texel(int x, int y) const { return texels_[size_t(y) * size_t(width_) + size_t(x)]; }
  /// A light-space direction from the importance distribution, with its (u, v) and the solid-angle
  /// density of the cell it was drawn from. False when the map is black.
  bool sample_direction(Vec2 u, Vec3& d_light, Vec2& uv, float& pdf) const;
  /// Solid-angle density in light space at cell coordinates.
  float pdf_light(Vec3 d) const;

  int width_ = 0, height_ = 0;
  HugeVector<Rgb> texels_;         // already multiplied by scale; huge pages: looked up at random
  std::vector<double> row_cos_;   // cos(theta) at each row, height_ entries
  std::vector<float> inv_cell_solid_angle_;  // per cell row: unit-square pdf -> solid-angle pdf
  Distribution2D distribution_;    // over width_ x (height_ - 1) cells
  double weight_sum_ = 0;          // sum of the cell weights: integral of luminance over the sphere / dphi
  float m_[3][3], inv_[3][3];      // world_from_light / light_from_world, linear part
  Vec3 center_;
  float radius_ = 1.f;
};

}  // namespace tessera
