// Analytic spheres (world space: the builder folds to_world into centre and radius).
#include "tessera/core/check.h"
#include "tessera/render/shape.h"

#include <cmath>

namespace tessera {

SphereShape::SphereShape(Vec3 center, float radius, bool flip_normals)
    : center_(center), radius_(radius), flip_(flip_normals) {
  TESSERA_CHECK(radius > 0.f && std::isfinite(radius));
  TESSERA_CHECK(is_finite(center));
}

Bounds3 SphereShape::bounds() const {
  Bounds3 b;
  b.extend(center_ - Vec3(radius_));
  b.extend(center_ + Vec3(radius_));
  return b;
}

void SphereShape::sample_area(Vec2 u, Vec3& p, Vec3& n, float& pdf_area) const {
  Vec3 d = square_to_uniform_sphere(u);
  p = center_ + d * radius_;
  n = flip_ ? -d : d;
  pdf_area = 1.f / area();
}

Vec3 SphereShape::reproject(Vec3 p, Vec3& p_error, Vec3* unit) const {
  const Vec3 d = p - center_;
  const float l2 = length_squared(d);
  // A point exactly at the centre cannot come from a real hit or sample; guard anyway.
  const Vec3 n = l2 > 0.f ? d / std::sqrt(l2) : Vec3(0.f, 0.f, 1.f);
  if (unit) *unit = n;
  const Vec3 q = n * radius_;
  const Vec3 out = center_ + q;
  // q: squares, sum, sqrt, division, product: within gamma(5) of r d/|d| per axis (the error in
  // d only turns it, along the surface). Adding the centre rounds once more.
  p_error = vabs(q) * error_gamma(5) + vabs(out) * error_gamma(1);
  return out;
}

void SphereShape::fill_interaction(const Ray& ray, const Hit& hit, uint32_t prim,
                                   SurfaceInteraction& si) const {
  // Re-project onto the surface: ray.at(t) carries the error of t (Mitsuba does the same).
  Vec3 n;
  si.p = reproject(ray.at(hit.t), si.p_error, &n);
  si.t = hit.t;
  si.ng = flip_ ? -n : n;
  si.shading = Frame(si.ng);
  // Mitsuba's spherical map in the sphere's axis-aligned frame: u = phi / 2pi, v = theta / pi.
  float phi = std::atan2(n.y, n.x);
  if (phi < 0.f) phi += 2.f * kPi;
  float theta = std::acos(std::fmin(1.f, std::fmax(-1.f, n.z)));
  si.uv = Vec2(phi * kInv2Pi, theta * kInvPi);
  // Derivatives of p = c + r (sin v*pi cos u*2pi, sin v*pi sin u*2pi, cos v*pi); they vanish or
  // lose their direction at the poles, where any tangent pair will do.
  const Vec3 q = n * radius_;
  const float rxy = std::sqrt(q.x * q.x + q.y * q.y);
  if (rxy > 1e-6f * radius_) {
    const float cos_phi = q.x / rxy, sin_phi = q.y / rxy;
    si.dpdu = Vec3(-q.y, q.x, 0.f) * (2.f * kPi);
    si.dpdv = Vec3(q.z * cos_phi, q.z * sin_phi, -rxy) * kPi;
  } else {
    coordinate_system(si.ng, si.dpdu, si.dpdv);
  }
  si.wo = normalize(-ray.d);
  si.shape = this;
  si.prim = prim;
}

}  // namespace tessera
