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

// Constants of Wächter and Binder (Ray Tracing Gems, ch. 6). Near the world origin, where float
// spacing is tiny, a fixed offset (float_scale) replaces the ULP offset, which would be too small.
constexpr float kOrigin = 1.f / 32.f;
constexpr float kFloatScale = 1.f / 65536.f;
constexpr float kIntScale = 256.f;

float offset_component(float p, float n) {
  if (std::abs(p) < kOrigin) return p + kFloatScale * n;
  // Moving the bit pattern by k moves the float by k ULPs, away from zero for a positive k on a
  // positive float and towards zero on a negative one: flip the step for negative p.
  const int32_t of_i = int32_t(kIntScale * n);
  const int32_t bits = std::bit_cast<int32_t>(p);
  return std::bit_cast<float>(bits + (p < 0.f ? -of_i : of_i));
}

}  // namespace

Vec3 offset_ray_origin(Vec3 p, Vec3 n) {
  return {offset_component(p.x, n.x), offset_component(p.y, n.y), offset_component(p.z, n.z)};
}

Ray spawn_ray(Vec3 p, Vec3 ng, Vec3 d) {
  Ray r;
  r.o = offset_ray_origin(p, dot(d, ng) < 0.f ? -ng : ng);
  r.d = d;
  return r;
}

/// The direction is target - origin (not normalised) and the segment is t in [0, 1 - 1e-4]: it
/// stops 1e-4 of the distance short of the target (as pbrt's ShadowEpsilon), so a ray towards a
/// point sampled on a light does not hit the light's own surface there.
Ray spawn_ray_to(Vec3 p, Vec3 ng, Vec3 target) {
  constexpr float kShadowEpsilon = 1e-4f;
  Ray r;
  r.o = offset_ray_origin(p, dot(target - p, ng) < 0.f ? -ng : ng);
  r.d = target - r.o;
  r.tmax = 1.f - kShadowEpsilon;
  return r;
}

}  // namespace tessera
