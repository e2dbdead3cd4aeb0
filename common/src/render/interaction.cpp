#include "tessera/render/interaction.h"

#include "tessera/render/shape.h"

#include <bit>
#include <cmath>
#include <cstdint>

namespace tessera {

bool reconcile_shading_frame(SurfaceInteraction& si, Vec3 wo_world, bool strict_normals) {
  if (consistent_side(si, wo_world, si.to_local(wo_world))) return true;
  if (strict_normals) return false;
  si.shading = Frame(si.ng);
  return true;
}

const Bsdf* SurfaceInteraction::bsdf() const { return shape ? shape->bsdf : nullptr; }
const Light* SurfaceInteraction::area_light() const { return shape ? shape->area_light(prim) : nullptr; }

namespace {

// pbrt-v4's NextFloatUp/NextFloatDown: the adjacent float (+0 and -0 treated alike; infinities
// stay). Bit stepping instead of std::nextafter keeps the hot path branch-light.
inline float next_float_up(float v) {
  if (std::isinf(v) && v > 0.f) return v;
  if (v == -0.f) v = 0.f;
  uint32_t ui = std::bit_cast<uint32_t>(v);
  ui = v >= 0.f ? ui + 1 : ui - 1;
  return std::bit_cast<float>(ui);
}

inline float next_float_down(float v) {
  if (std::isinf(v) && v < 0.f) return v;
  if (v == 0.f) v = -0.f;
  uint32_t ui = std::bit_cast<uint32_t>(v);
  ui = v > 0.f ? ui - 1 : ui + 1;
  return std::bit_cast<float>(ui);
}

// Shadow rays stop this fraction of their length short of the (offset) target. Both ends are
// already off their surfaces by their error bounds and the BVH computes t in double from float
// vertices, so this only has to absorb the rounding of t itself (a few float ulps of 1); pbrt's
// 1e-4 would let a shadow ray stop before a wall 1e-4 of its length in front of the light.
constexpr float kShadowEpsilon = 1.f / 1048576.f;  // 2^-20, ~9.5e-7

}  // namespace

Vec3 offset_ray_origin(Vec3 p, Vec3 p_error, Vec3 n, Vec3 w) {
  const float d = dot(vabs(n), p_error);
  Vec3 offset = n * d;
  if (dot(w, n) < 0.f) offset = -offset;
  Vec3 po = p + offset;
  // The sum rounds to nearest, possibly back towards the surface: step each moved coordinate
  // one float further away.
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.f) po[i] = next_float_up(po[i]);
    else if (offset[i] < 0.f) po[i] = next_float_down(po[i]);
  }
  return po;
}

Ray spawn_ray(Vec3 p, Vec3 p_error, Vec3 ng, Vec3 d) {
  Ray r;
  r.o = offset_ray_origin(p, p_error, ng, d);
  r.d = d;
  return r;
}

Ray spawn_ray_to(Vec3 p, Vec3 p_error, Vec3 ng, Vec3 target, Vec3 target_error, Vec3 target_n) {
  Ray r;
  r.o = offset_ray_origin(p, p_error, ng, target - p);
  const Vec3 pt = target_n == Vec3(0.f) ? target : offset_ray_origin(target, target_error, target_n, r.o - target);
  r.d = pt - r.o;
  r.tmax = 1.f - kShadowEpsilon;
  return r;
}

Vec3 estimated_point_error(Vec3 p) {
  return Vec3(error_gamma(7) * max_component(vabs(p)));
}

Ray spawn_ray(Vec3 p, Vec3 ng, Vec3 d) { return spawn_ray(p, estimated_point_error(p), ng, d); }

Ray spawn_ray_to(Vec3 p, Vec3 ng, Vec3 target) {
  // The target is not offset (its surface is unknown here), so the segment keeps pbrt's 1e-4
  // margin before it, as before the error bounds.
  constexpr float kUnoffsetTargetEpsilon = 1e-4f;
  Ray r = spawn_ray_to(p, estimated_point_error(p), ng, target, Vec3(0.f), Vec3(0.f));
  r.tmax = 1.f - kUnoffsetTargetEpsilon;
  return r;
}

}  // namespace tessera
