// What the emitters share when sampled from a reference point: the geometry of a delta emitter at a
// point (point, spot), and of a one-sided emitting surface point (whole-shape and triangle area
// lights) with the area-to-solid-angle change of measure for its pdf. And what they share when
// sampled for emission (Light::sample_le): cosine-weighted directions off a diffuse surface, and
// the disk that distant lights (envmap, sunsky, constant, directional) emit from.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/frame.h"
#include "tessera/core/sampling.h"
#include "tessera/render/light.h"

#include <algorithm>
#include <cmath>

namespace tessera::detail {

/// Fills `out` for a delta emitter at `position` seen from `ref_p`, with li = 1 / d^2: the caller
/// multiplies by the intensity it emits towards ref_p. False when the points coincide.
inline bool point_emitter_sample(Vec3 position, Vec3 ref_p, LightSample& out) {
  const Vec3 d = position - ref_p;
  const float dist2 = length_squared(d);
  if (!(dist2 > 0.f)) return false;
  const float dist = std::sqrt(dist2);
  out.wi = d / dist;
  out.li = Rgb(1.f / dist2);
  out.p_light = position;
  out.p_light_error = Vec3(0.f);
  out.n_light = Vec3(0.f);
  out.dist = dist;
  out.pdf = 1.f;
  out.delta = true;
  return true;
}

/// Fills `out` for the light point `p` (geometric normal `n`, emitting towards +n) seen from
/// `ref_p`. `pdf` is per unit area on the light when `pdf_is_area`, else already per solid angle.
/// False when the point is behind its surface (one-sided emission), coincident, or the density is
/// not a positive finite number.
inline bool emission_sample(Vec3 ref_p, Vec3 p, Vec3 n, float pdf, bool pdf_is_area, Rgb radiance,
                            LightSample& out) {
  const Vec3 d = p - ref_p;
  const float dist2 = length_squared(d);
  if (!(dist2 > 0.f)) return false;
  const float dist = std::sqrt(dist2);
  const Vec3 wi = d / dist;
  const float cos_light = -dot(n, wi);
  if (!(cos_light > 0.f)) return false;
  if (pdf_is_area) pdf *= dist2 / cos_light;
  out.wi = wi;
  out.li = radiance;
  out.p_light = p;
  out.p_light_error = Vec3(0.f);  // the caller knows the bound of its point
  out.n_light = n;
  out.dist = dist;
  out.pdf = pdf;
  out.delta = false;
  return std::isfinite(pdf) && pdf > 0.f;
}

/// Solid-angle density at `ref_p` of a point `si` on the light sampled with area density
/// `pdf_area`; 0 where the conversion degenerates.
inline float area_pdf_to_solid_angle(Vec3 ref_p, const SurfaceInteraction& si, float pdf_area) {
  const Vec3 d = si.p - ref_p;
  const float dist2 = length_squared(d);
  if (!(dist2 > 0.f)) return 0.f;
  const float cos_light = std::abs(dot(si.ng, d)) / std::sqrt(dist2);
  if (!(cos_light > 0.f)) return 0.f;
  const float pdf = pdf_area * dist2 / cos_light;
  return std::isfinite(pdf) ? pdf : 0.f;
}

/// Uniform density per unit area on a surface of area `area`; 0 when there is no surface (zero
/// or non-finite area, or an area so small its inverse overflows) to emit from.
inline float inverse_area(float area) {
  const float pdf = 1.f / area;
  return area > 0.f && std::isfinite(pdf) ? pdf : 0.f;
}

/// Density per unit solid angle of a direction `dir` leaving a diffuse one-sided emitter with
/// geometric normal `n`: cos / pi on the emitting side, 0 behind it. sample_le and pdf_le both
/// compute it from the world-space dot product, so the two agree to the bit.
inline float cosine_emission_pdf(Vec3 n, Vec3 dir) { return std::max(dot(n, dir), 0.f) * kInvPi; }

/// Completes `out` for light leaving the surface point `out.p` (normal `n`, emitting towards +n):
/// a cosine-weighted direction from `u`. False when the direction grazes the surface (pdf 0).
inline bool cosine_emission(Vec3 n, Vec2 u, float pdf_pos, Rgb radiance, LightEmission& out) {
  out.dir = normalize(Frame(n).to_world(square_to_cosine_hemisphere(u)));
  out.n = n;
  out.le = radiance;
  out.pdf_pos = pdf_pos;
  out.pdf_dir = cosine_emission_pdf(n, out.dir);
  out.delta_pos = out.delta_dir = out.infinite = false;
  return out.pdf_dir > 0.f && std::isfinite(pdf_pos) && pdf_pos > 0.f;
}

/// Where a distant light's rays start: the disk of the scene's bounding-sphere radius facing the
/// direction of travel, one radius behind the sphere, so that every ray through the disk along
/// `dir` covers the whole scene and pdf_pos = 1 / (pi R^2) is uniform over its cross-section.
struct EmissionDisk {
  Vec3 center;
  float radius = 0.f;

  static EmissionDisk around(const Bounds3& scene_bounds) {
    if (scene_bounds.empty()) return {};
    return {scene_bounds.center(), 0.5f * length(scene_bounds.diagonal())};
  }
  /// 0 for a scene without extent (nothing to light; sample_le then fails).
  float pdf_pos() const {
    const float pdf = 1.f / (kPi * radius * radius);
    return radius > 0.f && std::isfinite(pdf) ? pdf : 0.f;
  }
  /// Sets out.p, n, p_error, pdf_pos and the flags of a ray along the unit `dir`; the caller sets
  /// le, pdf_dir and delta_dir. False when the disk is degenerate.
  bool sample(Vec3 dir, Vec2 u, LightEmission& out) const {
    out.pdf_pos = pdf_pos();
    if (!(out.pdf_pos > 0.f)) return false;
    const Frame frame(dir);
    const Vec2 d = square_to_uniform_disk_concentric(u);
    out.p = center + (frame.s * d.x + frame.t * d.y - dir) * radius;
    out.n = dir;
    out.p_error = Vec3(0.f);
    out.dir = dir;
    out.delta_pos = false;
    out.infinite = true;
    return true;
  }
};

}  // namespace tessera::detail
