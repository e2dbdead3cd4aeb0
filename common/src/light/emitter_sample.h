// What the emitters share when sampled from a reference point: the geometry of a delta emitter at a
// point (point, spot), and of a one-sided emitting surface point (whole-shape and triangle area
// lights) with the area-to-solid-angle change of measure for its pdf.
#pragma once

#include "tessera/render/light.h"

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

}  // namespace tessera::detail
