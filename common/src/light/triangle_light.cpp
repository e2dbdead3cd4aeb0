// Area light on a single mesh triangle: the same emission as the mesh-wide `area` light (front side
// only, constant radiance), sampled uniformly by area over this triangle alone. For constant
// radiance, picking triangles by power and then a point by area is the mesh-wide light's density
// exactly, so splitting changes no expected value.
#include "tessera/light/triangle_light.h"

#include "light/emitter_sample.h"

#include "tessera/core/sampling.h"
#include "tessera/render/light_bounds.h"

#include <cmath>

namespace tessera {
namespace {

class TriangleLight final : public Light {
 public:
  TriangleLight(const TriangleMeshShape& mesh, uint32_t tri, Rgb radiance) : radiance_(radiance) {
    const MeshData& m = mesh.mesh();
    const uint32_t* idx = &m.indices[3 * size_t(tri)];
    p0_ = m.positions[idx[0]];
    p1_ = m.positions[idx[1]];
    p2_ = m.positions[idx[2]];
    const Vec3 c = cross(p1_ - p0_, p2_ - p0_);
    const float len = length(c);
    area_ = 0.5f * len;
    if (!(len > 0.f) || !std::isfinite(len)) {
      area_ = 0.f;
      n_ = Vec3(0.f, 0.f, 1.f);
    } else {
      n_ = c / len;
    }
    if (mesh.flip_normals()) n_ = -n_;
  }

  bool sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const override {
    if (!(area_ > 0.f)) return false;
    const Vec2 b = square_to_uniform_triangle(u);
    const float b0 = 1.f - b.x - b.y;
    const Vec3 p = p0_ * b0 + p1_ * b.x + p2_ * b.y;
    if (!detail::emission_sample(ref_p, p, n_, 1.f / area_, /*pdf_is_area=*/true, radiance_, out)) return false;
    out.p_light_error = barycentric_point_error(p0_, p1_, p2_, b0, b.x, b.y);
    return true;
  }

  Rgb le(const SurfaceInteraction& si, Vec3 w) const override {
    return dot(si.ng, w) > 0.f ? radiance_ : Rgb();
  }

  float pdf_li(Vec3 ref_p, const SurfaceInteraction& si) const override {
    if (!(area_ > 0.f)) return 0.f;
    return detail::area_pdf_to_solid_angle(ref_p, si, 1.f / area_);
  }

  // Emission: uniform by area, then cosine-weighted about the (one-sided) normal.
  bool sample_le(Vec2 u_pos, Vec2 u_dir, LightEmission& out) const override {
    const float pdf_pos = detail::inverse_area(area_);
    if (!(pdf_pos > 0.f) || radiance_.is_black()) return false;
    const Vec2 b = square_to_uniform_triangle(u_pos);
    const float b0 = 1.f - b.x - b.y;
    out.p = p0_ * b0 + p1_ * b.x + p2_ * b.y;
    out.p_error = barycentric_point_error(p0_, p1_, p2_, b0, b.x, b.y);
    return detail::cosine_emission(n_, u_dir, pdf_pos, radiance_, out);
  }

  void pdf_le(Vec3, Vec3 n, Vec3 dir, float& pdf_pos, float& pdf_dir) const override {
    pdf_pos = detail::inverse_area(area_);
    pdf_dir = detail::cosine_emission_pdf(n, dir);
  }

  float power() const override { return kPi * area_ * radiance_.luminance(); }

  bool light_bounds(LightBounds& out) const override {
    out.bounds = Bounds3();
    out.bounds.extend(p0_);
    out.bounds.extend(p1_);
    out.bounds.extend(p2_);
    out.w = n_;
    out.phi = power();
    out.cos_theta_o = 1.f;  // a single normal
    out.cos_theta_e = 0.f;  // diffuse: up to 90 degrees from it
    out.two_sided = false;
    return out.phi > 0.f;
  }

 private:
  Vec3 p0_, p1_, p2_, n_;
  float area_ = 0.f;
  Rgb radiance_;
};

}  // namespace

std::unique_ptr<Light> make_triangle_light(const TriangleMeshShape& mesh, uint32_t tri, Rgb radiance) {
  return std::make_unique<TriangleLight>(mesh, tri, radiance);
}

}  // namespace tessera
