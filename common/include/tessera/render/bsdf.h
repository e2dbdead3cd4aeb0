// BSDF interface.
//
// Frames: every method takes `wo` and `wi` in the local shading frame of `si` (normal on +z),
// both unit length and pointing away from the surface. The caller converts with si.to_local.
// eval() INCLUDES the cosine foreshortening |cos theta_i| (Mitsuba convention).
// pdf() is a density with respect to SOLID ANGLE of wi; for delta components it is not defined
// (sample() reports them with `delta = true` and eval()/pdf() return 0 for them).
// Hot path: no method throws or allocates.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/render/interaction.h"

namespace tessera {

struct BsdfSample {
  Vec3 wi;           // local frame
  float pdf = 0.f;   // solid angle; for a delta lobe, the discrete probability of choosing it
  Rgb weight;        // eval * |cos| / pdf (for delta lobes: the lobe's throughput / probability)
  bool delta = false;
  /// Relative IOR crossed by a refraction (n on the wi side over n on the wo side, Mitsuba 0.6's
  /// bRec.eta); 1 for reflection. The path tracer multiplies these along the path to undo the
  /// 1/eta^2 radiance scaling in Russian roulette.
  float eta = 1.f;
};

class Bsdf {
 public:
  virtual ~Bsdf() = default;
  virtual Rgb eval(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const = 0;
  virtual float pdf(const SurfaceInteraction& si, Vec3 wo, Vec3 wi) const = 0;
  /// `u1` picks a lobe, `u2` the direction within it. False when no direction could be sampled.
  virtual bool sample(const SurfaceInteraction& si, Vec3 wo, float u1, Vec2 u2,
                      BsdfSample& out) const = 0;
  /// True when every lobe is a delta (no next-event estimation possible).
  virtual bool is_delta() const { return false; }
  /// How rough the roughest non-delta lobe is at `si`, in [0, 1]: 1 for a diffuse lobe, a
  /// microfacet lobe's alpha (the smaller of an anisotropic pair), 0 when every lobe is a delta.
  /// For strategies that pay only on rough surfaces (vcm's vertex merging, vcm.h).
  virtual float roughness(const SurfaceInteraction&) const { return is_delta() ? 0.f : 1.f; }
  /// True when the BSDF (Mitsuba's `mask`, or a wrapper around one) lets part of the light pass
  /// straight through the surface. Wrappers (twosided, bumpmap, ...) must forward both methods.
  virtual bool has_opacity() const { return false; }
  /// Fraction of light the surface stops at `si`, in [0, 1]. The integrator applies it, not
  /// eval()/sample(): a ray hitting the surface passes through with probability 1 - opacity
  /// (Scene::intersect), and shadow rays are attenuated by 1 - opacity (Scene::transmittance).
  /// So eval()/pdf()/sample() of a masked BSDF describe the opaque part only.
  virtual float opacity(const SurfaceInteraction&) const { return 1.f; }
  /// True for Mitsuba's `null` BSDF: an index-matched boundary (the surface of a medium) that rays
  /// cross unchanged. It has opacity 0, so an integrator that does not track media, and every
  /// shadow ray, passes it like a fully transparent mask; the volume path tracer stops there to
  /// switch media (Scene::intersect with `stop_at_null`).
  virtual bool is_null() const { return false; }
};

}  // namespace tessera
