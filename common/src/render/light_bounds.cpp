// Cone arithmetic and the importance bound. Angles are carried as (sin, cos) pairs in the hot
// importance() so that it needs no trigonometric calls; the merges, done at build time only, use
// angles.
#include "tessera/render/light_bounds.h"

#include "tessera/core/sampling.h"

#include <algorithm>
#include <cmath>

namespace tessera {
namespace {

inline float safe_sqrt(float x) { return std::sqrt(std::max(0.f, x)); }
inline float safe_acos(float x) { return std::acos(std::clamp(x, -1.f, 1.f)); }

// Angle between unit vectors, accurate near 0 and pi (where acos(dot) is not).
float angle_between(Vec3 a, Vec3 b) {
  if (dot(a, b) < 0.f) return kPi - 2.f * std::asin(std::min(1.f, length(a + b) * 0.5f));
  return 2.f * std::asin(std::min(1.f, length(b - a) * 0.5f));
}

// Rodrigues' rotation of v by `angle` about the unit axis k.
Vec3 rotate(Vec3 v, Vec3 k, float angle) {
  float c = std::cos(angle), s = std::sin(angle);
  return v * c + cross(k, v) * s + k * (dot(k, v) * (1.f - c));
}

// cos(max(0, a - b)) and sin(max(0, a - b)) from the sines and cosines of a, b in [0, pi].
inline float cos_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 1.f;  // a < b
  return cos_a * cos_b + sin_a * sin_b;
}
inline float sin_sub_clamped(float sin_a, float cos_a, float sin_b, float cos_b) {
  if (cos_a > cos_b) return 0.f;
  return sin_a * cos_b - cos_a * sin_b;
}

}  // namespace

DirectionCone merge(const DirectionCone& a, const DirectionCone& b) {
  const float theta_a = safe_acos(a.cos_theta), theta_b = safe_acos(b.cos_theta);
  const float theta_d = angle_between(a.w, b.w);
  if (std::min(theta_d + theta_b, kPi) <= theta_a) return a;
  if (std::min(theta_d + theta_a, kPi) <= theta_b) return b;
  // The merged cone spans from a's far edge to b's far edge; its axis is a.w turned towards b.w.
  const float theta_o = 0.5f * (theta_a + theta_d + theta_b);
  if (theta_o >= kPi) return DirectionCone::sphere();
  const Vec3 axis = cross(a.w, b.w);
  const float axis_len = length(axis);
  if (!(axis_len > 0.f) || !std::isfinite(axis_len)) return DirectionCone::sphere();
  DirectionCone c;
  c.w = normalize(rotate(a.w, axis / axis_len, theta_o - theta_a));
  // Rounding in the rotation must not make the cone miss its inputs' edges.
  c.cos_theta = std::max(-1.f, std::cos(theta_o) - 1e-5f);
  return c;
}

DirectionCone bound_subtended_directions(const Bounds3& b, Vec3 p) {
  const Vec3 c = b.center();
  const float r2 = length_squared(b.hi - c);
  const float d2 = length_squared(p - c);
  if (b.contains(p) || d2 <= r2) return DirectionCone::sphere();
  const float sin2_max = r2 / d2;
  return {(c - p) / std::sqrt(d2), safe_sqrt(1.f - sin2_max)};
}

float LightBounds::importance(Vec3 p, Vec3 n) const {
  if (!(phi > 0.f)) return 0.f;
  const Vec3 pc = centroid();
  const Vec3 d = p - pc;
  const float dist2 = length_squared(d);
  // Clamp to the cluster's squared radius: inside a cluster, distance says nothing (and 1/d^2
  // would blow up next to a small emitter).
  const float radius2 = 0.25f * length_squared(bounds.diagonal());
  const float d2 = std::max(dist2, radius2);
  const Vec3 wi = dist2 > 0.f ? d / std::sqrt(dist2) : w;

  // Minimum angle between an emitter normal and the direction to p, less what the box subtends.
  float cos_w = dot(w, wi);
  if (two_sided) cos_w = std::abs(cos_w);
  const float sin_w = safe_sqrt(1.f - cos_w * cos_w);
  // What the box's bounding sphere subtends (bound_subtended_directions, inlined: the hot path
  // needs only its angle). Inside it, every direction.
  float cos_b = -1.f, sin_b = 0.f;
  if (dist2 > radius2) {
    const float sin2_b = radius2 / dist2;
    sin_b = std::sqrt(sin2_b);
    cos_b = safe_sqrt(1.f - sin2_b);
  }
  const float sin_o = safe_sqrt(1.f - cos_theta_o * cos_theta_o);
  const float cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_theta_o);
  const float sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_theta_o);
  const float cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
  if (cos_p <= cos_theta_e) return 0.f;

  float importance = phi * cos_p / d2;
  if (n.x != 0.f || n.y != 0.f || n.z != 0.f) {
    // |cos| at the receiver, bounded the same way (abs: transmissive surfaces see both sides).
    const float cos_i = abs_dot(wi, n);
    const float sin_i = safe_sqrt(1.f - cos_i * cos_i);
    importance *= cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
  }
  return std::isfinite(importance) ? std::max(importance, 0.f) : 0.f;
}

LightBounds merge(const LightBounds& a, const LightBounds& b) {
  if (!(a.phi > 0.f)) return b;
  if (!(b.phi > 0.f)) return a;
  LightBounds m;
  m.bounds = tessera::merge(a.bounds, b.bounds);
  m.phi = a.phi + b.phi;
  const DirectionCone c = merge(DirectionCone{a.w, a.cos_theta_o}, DirectionCone{b.w, b.cos_theta_o});
  m.w = c.w;
  m.cos_theta_o = c.cos_theta;
  m.cos_theta_e = std::min(a.cos_theta_e, b.cos_theta_e);
  m.two_sided = a.two_sided || b.two_sided;
  return m;
}

}  // namespace tessera
