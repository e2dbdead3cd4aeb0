// Mitsuba's `area` emitter: constant radiance leaving the front (geometric-normal) side of a shape.
//
// Sampling: by area on the shape, converted to solid angle (pdf_area d^2 / |cos at the light|).
// Spheres seen from outside instead sample the cone of directions they subtend (pbrt-v4's
// Sphere::Sample): every sample lands on the visible cap, where uniform area sampling would waste
// the half of its samples that fall on the hidden side, and the density is smooth.
// Emission sampling (sample_le) is uniform by area on every shape, with cosine-weighted directions.
#include "tessera/light/area.h"

#include "light/emitter_sample.h"

#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/render/light_bounds.h"
#include "tessera/light/triangle_light.h"
#include "tessera/scene/load_context.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

// Below sin^2(theta_max) ~ sin^2(1.5 deg) the cone's 1 - cos(theta_max) loses all precision in
// float; a first-order expansion in sin^2 replaces it (as pbrt-v4 does).
constexpr float kSmallCone = 0.00068523f;

struct Cone {
  float sin2_max = 0.f, cos_max = 1.f, one_minus_cos_max = 0.f;
};

inline Cone sphere_cone(float dist2_center, float radius) {
  Cone c;
  c.sin2_max = std::min(1.f, radius * radius / dist2_center);
  c.cos_max = std::sqrt(std::max(0.f, 1.f - c.sin2_max));
  c.one_minus_cos_max = c.sin2_max < kSmallCone ? 0.5f * c.sin2_max : 1.f - c.cos_max;
  return c;
}

class AreaLight final : public Light {
 public:
  AreaLight(const Shape& shape, Rgb radiance) : shape_(shape), radiance_(radiance) {
    if (shape.kind() == Shape::Kind::Sphere) {
      sphere_ = static_cast<const SphereShape*>(&shape);
      // Whether the sphere's normals are flipped is not part of the Shape interface; the normal
      // sample_area returns tells it (outward unless flipped).
      Vec3 p, n;
      float pdf = 0.f;
      shape.sample_area({0.3f, 0.6f}, p, n, pdf);
      sphere_flipped_ = dot(n, p - sphere_->center()) < 0.f;
    } else {
      // Shape::sample_area gives no error bound; any barycentric point of the mesh is within
      // error_gamma(10) max |vertex| per axis (barycentric_point_error with b summing to 1).
      const Bounds3 b = shape.bounds();
      if (!b.empty()) mesh_error_ = vmax(vabs(b.lo), vabs(b.hi)) * error_gamma(10);
    }
  }

  bool sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const override {
    Vec3 p, n;
    float pdf = 0.f;
    const bool cone = sphere_ && outside_sphere(ref_p);
    if (cone) {
      if (!sample_sphere_cone(ref_p, u, p, n, pdf)) return false;
    } else {
      float pdf_area = 0.f;
      shape_.sample_area(u, p, n, pdf_area);
      if (!(pdf_area > 0.f)) return false;
      pdf = pdf_area;  // converted below, once the distance is known
    }
    Vec3 p_error = mesh_error_;
    if (sphere_) p = sphere_->reproject(p, p_error);
    if (!detail::emission_sample(ref_p, p, n, pdf, /*pdf_is_area=*/!cone, radiance_, out)) return false;
    out.p_light_error = p_error;
    return true;
  }

  Rgb le(const SurfaceInteraction& si, Vec3 w) const override {
    return dot(si.ng, w) > 0.f ? radiance_ : Rgb();
  }

  float pdf_li(Vec3 ref_p, const SurfaceInteraction& si) const override {
    if (sphere_ && outside_sphere(ref_p)) {
      Cone c = sphere_cone(length_squared(sphere_->center() - ref_p), sphere_->radius());
      return 1.f / (2.f * kPi * c.one_minus_cos_max);
    }
    // Shapes sample uniformly by area (see Shape::sample_area).
    return detail::area_pdf_to_solid_angle(ref_p, si, 1.f / shape_.area());
  }

  // Emission: uniform by area over the whole shape (spheres too: a light path has no reference
  // point to aim a cone from), then cosine-weighted about the geometric normal.
  bool sample_le(Vec2 u_pos, Vec2 u_dir, LightEmission& out) const override {
    const float pdf_pos = detail::inverse_area(shape_.area());
    if (!(pdf_pos > 0.f) || radiance_.is_black()) return false;
    Vec3 p, n;
    float pdf_area = 0.f;
    shape_.sample_area(u_pos, p, n, pdf_area);
    if (!(pdf_area > 0.f)) return false;
    out.p_error = mesh_error_;
    out.p = sphere_ ? sphere_->reproject(p, out.p_error) : p;
    return detail::cosine_emission(n, u_dir, pdf_pos, radiance_, out);
  }

  void pdf_le(Vec3, Vec3 n, Vec3 dir, float& pdf_pos, float& pdf_dir) const override {
    pdf_pos = detail::inverse_area(shape_.area());
    pdf_dir = detail::cosine_emission_pdf(n, dir);
  }

  float power() const override { return kPi * shape_.area() * radiance_.luminance(); }

  // Whole shapes: a sphere (or an unsplit mesh) may emit in every direction.
  bool light_bounds(LightBounds& out) const override {
    out.bounds = shape_.bounds();
    out.w = Vec3(0.f, 0.f, 1.f);
    out.phi = power();
    out.cos_theta_o = -1.f;
    out.cos_theta_e = 0.f;
    out.two_sided = false;
    return out.phi > 0.f && !out.bounds.empty();
  }

  std::vector<std::unique_ptr<Light>> make_primitive_lights() const override {
    std::vector<std::unique_ptr<Light>> out;
    if (shape_.kind() != Shape::Kind::Mesh) return out;
    const auto& mesh = static_cast<const TriangleMeshShape&>(shape_);
    out.reserve(mesh.num_primitives());
    for (uint32_t t = 0; t < mesh.num_primitives(); ++t) out.push_back(make_triangle_light(mesh, t, radiance_));
    return out;
  }

 private:
  bool outside_sphere(Vec3 ref_p) const {
    float r = sphere_->radius();
    // A reference point on the sphere itself (e.g. a hit on the light) counts as inside: the
    // cone degenerates to a hemisphere there.
    return length_squared(ref_p - sphere_->center()) > r * r * 1.0001f;
  }

  bool sample_sphere_cone(Vec3 ref_p, Vec2 u, Vec3& p, Vec3& n, float& pdf) const {
    const Vec3 c = sphere_->center();
    const float r = sphere_->radius();
    const Vec3 to_center = c - ref_p;
    const float dc2 = length_squared(to_center);
    const Cone cone = sphere_cone(dc2, r);
    // Direction in the cone around the centre direction, theta measured from it.
    float sin2_theta, cos_theta;
    if (cone.sin2_max < kSmallCone) {
      sin2_theta = cone.sin2_max * u.x;
      cos_theta = std::sqrt(1.f - sin2_theta);
    } else {
      cos_theta = (1.f - u.x) + u.x * cone.cos_max;
      sin2_theta = std::max(0.f, 1.f - cos_theta * cos_theta);
    }
    // Angle alpha at the centre between -to_center and the hit point (first intersection).
    const float sin_theta_max = std::sqrt(cone.sin2_max);
    float cos_alpha = sin2_theta / sin_theta_max +
                      cos_theta * std::sqrt(std::max(0.f, 1.f - sin2_theta / cone.sin2_max));
    cos_alpha = std::clamp(cos_alpha, -1.f, 1.f);
    const float sin_alpha = std::sqrt(std::max(0.f, 1.f - cos_alpha * cos_alpha));
    const float phi = 2.f * kPi * u.y;
    const Frame frame(to_center / std::sqrt(dc2));
    // Outward normal at the sampled point, in the frame whose +z points from ref to the centre.
    const Vec3 n_out = frame.to_world(Vec3(-sin_alpha * std::cos(phi), -sin_alpha * std::sin(phi), -cos_alpha));
    p = c + n_out * r;
    n = sphere_flipped_ ? -n_out : n_out;
    pdf = 1.f / (2.f * kPi * cone.one_minus_cos_max);
    return std::isfinite(pdf);
  }

  const Shape& shape_;
  const SphereShape* sphere_ = nullptr;
  bool sphere_flipped_ = false;
  Vec3 mesh_error_;  // error bound of any point sample_area returns on a mesh
  Rgb radiance_;
};

}  // namespace

std::unique_ptr<Light> make_area_light(const Shape& shape, Rgb radiance) {
  return std::make_unique<AreaLight>(shape, radiance);
}

// Mitsuba's `area` emitter: `radiance` (0.6 default: white 1).
std::unique_ptr<Light> make_area_light(const SceneNode& emitter, LoadContext&, const Shape& shape) {
  return make_area_light(shape, emitter.get_color("radiance", Rgb(1.f)));
}

}  // namespace tessera
