#include "perturbed_frame.h"

#include <cmath>

namespace tessera {

namespace {

/// v / |v| when |v|^2 is a positive finite number above `min_l2`, else false.
bool try_normalize(Vec3 v, float min_l2, Vec3& out) {
  float l2 = length_squared(v);
  if (!(l2 > min_l2) || !std::isfinite(l2)) return false;
  out = v / std::sqrt(l2);
  return true;
}

}  // namespace

Frame frame_from_normal(const SurfaceInteraction& si, Vec3 n) {
  Frame f;
  f.n = n;
  // Relative threshold: dp/du carries world units per uv unit, anything from 1e-3 to 1e3.
  const float du2 = length_squared(si.dpdu);
  if (!try_normalize(si.dpdu - n * dot(n, si.dpdu), 1e-10f * du2, f.s) &&
      !try_normalize(si.shading.s - n * dot(n, si.shading.s), 1e-6f, f.s)) {
    coordinate_system(n, f.s, f.t);
    return f;
  }
  f.t = cross(n, f.s);
  return f;
}

Frame bumped_frame(const SurfaceInteraction& si, Vec2 grad) {
  if (grad.x == 0.f && grad.y == 0.f) return si.shading;
  if (!std::isfinite(grad.x) || !std::isfinite(grad.y)) return si.shading;
  const Vec3 n = si.shading.n;
  // The displaced surface p + h n, its normal's own derivative neglected (Mitsuba 0.6): the
  // tangents lose their normal component and gain the height's slope instead.
  const Vec3 dpdu = si.dpdu + n * (grad.x - dot(n, si.dpdu));
  const Vec3 dpdv = si.dpdv + n * (grad.y - dot(n, si.dpdv));
  Frame f;
  if (!try_normalize(cross(dpdu, dpdv), 0.f, f.n)) return si.shading;
  if (!try_normalize(dpdu - f.n * dot(dpdu, f.n), 0.f, f.s)) f = frame_from_normal(si, f.n);
  else f.t = cross(f.n, f.s);
  if (!is_finite(f.s) || !is_finite(f.t)) return si.shading;
  // Mirrored uv layouts make cross(dpdu, dpdv) point inwards. Mitsuba flips n alone, leaving a
  // left-handed but still orthonormal frame; isotropic and mirror-symmetric lobes cannot tell.
  if (dot(f.n, si.ng) < 0.f) f.n = -f.n;
  return f;
}

Frame normal_mapped_frame(const SurfaceInteraction& si, Vec3 tangent_normal) {
  if (!is_finite(tangent_normal)) return si.shading;
  // A flat texel (0, 0, z > 0) keeps the shape's frame as it is, tangents included.
  if (tangent_normal.x == 0.f && tangent_normal.y == 0.f && tangent_normal.z > 0.f) return si.shading;
  const Frame tangent_space = frame_from_normal(si, si.shading.n);
  Vec3 n;
  if (!try_normalize(tangent_space.to_world(tangent_normal), 0.f, n)) return si.shading;
  return frame_from_normal(si, n);
}

Rgb PerturbedQuery::eval(const Bsdf& nested, Vec3 wo, Vec3 wi) const {
  const Vec3 wi_p = to_perturbed(wi);
  if (cos_theta(wi) * cos_theta(wi_p) <= 0.f) return {};
  return nested.eval(perturbed_, to_perturbed(wo), wi_p);
}

float PerturbedQuery::pdf(const Bsdf& nested, Vec3 wo, Vec3 wi) const {
  const Vec3 wi_p = to_perturbed(wi);
  if (cos_theta(wi) * cos_theta(wi_p) <= 0.f) return 0.f;
  return nested.pdf(perturbed_, to_perturbed(wo), wi_p);
}

bool PerturbedQuery::sample(const Bsdf& nested, Vec3 wo, float u1, Vec2 u2, BsdfSample& out) const {
  if (!nested.sample(perturbed_, to_perturbed(wo), u1, u2, out)) return false;
  const Vec3 wi = from_perturbed(out.wi);
  if (cos_theta(wi) * cos_theta(out.wi) <= 0.f) return false;
  out.wi = wi;
  return true;
}

}  // namespace tessera
