// Light (emitter) interface.
//
// sample_li() samples a direction from a reference point towards the light. Its `pdf` is with
// respect to SOLID ANGLE at the reference point; for delta lights (point) `pdf` is 1 and `delta`
// is set. `li` is the radiance arriving (not divided by the pdf). A caller that traces a shadow
// ray first may set `defer_li`: a light whose radiance costs memory traffic (an environment map's
// texels) then leaves `li` unset, sets `li_deferred`, and deferred_li() gives it, so an occluded
// sample never pays for it. The radiance is the same either way.
// Area lights and environment lights can also be hit by BSDF-sampled rays: le()/le_env() give the
// emitted radiance, and pdf_li()/pdf_env() the solid-angle density sample_li() would have had, for
// multiple importance sampling.
// Hot path: no method throws or allocates.
#pragma once

#include "tessera/core/bounds.h"
#include "tessera/core/rgb.h"
#include "tessera/core/vec.h"
#include "tessera/render/interaction.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace tessera {

struct LightBounds;  // render/light_bounds.h

struct LightSample {
  Rgb li;               // incident radiance along -wi arriving at the reference point
  Vec3 wi;              // unit, world space, from the reference point towards the light
  Vec3 p_light;         // point on the light (for infinite lights: far along wi)
  Vec3 n_light;         // surface normal at p_light (zero for point/infinite lights)
  Vec3 p_light_error;   // rounding-error bound of p_light per axis (SurfaceInteraction::p_error);
                        // zero for points not on a surface
  float dist = kInfinity;  // distance to p_light; kInfinity for infinite lights
  float pdf = 0.f;
  bool delta = false;
  bool defer_li = false;    // in: the caller asks deferred_li() for li when li_deferred is set
  bool li_deferred = false;
  Vec2 li_uv;               // where deferred_li() looks the radiance up (the light's own map)
};

/// A ray leaving a light, for light tracing and bidirectional methods (Light::sample_le).
/// The emitted weight of the sample is le * cos / (pdf_pos * pdf_dir), where cos = |dot(n, dir)| for
/// area lights and 1 for every other kind (their le already is per unit area perpendicular to dir).
struct LightEmission {
  Vec3 p;        // where the light leaves: on an area light's surface, at a point or spot light,
                 // or, for distant lights (envmap, sunsky, constant, directional), on a disk of the
                 // scene's bounding sphere's radius, facing `dir`, one radius behind the sphere
  Vec3 n;        // geometric normal at p (area lights, emitting side); `dir` for distant lights;
                 // zero for point and spot lights
  Vec3 p_error;  // rounding-error bound of p per axis (zero for points not on a surface)
  Vec3 dir;      // unit, world: the direction the light travels
  Rgb le;        // radiance leaving p along dir (area lights, environments); radiant intensity
                 // towards dir (point, spot); irradiance on a plane facing it (directional)
  float pdf_pos = 0.f;  // density of p per unit AREA (on the shape or on the disk); 1 for a delta
                        // position (point, spot)
  float pdf_dir = 0.f;  // density of dir per unit SOLID ANGLE given p; 1 for a delta direction
                        // (directional)
  bool delta_pos = false, delta_dir = false;
  bool infinite = false;  // a distant light (p on the disk)
};

/// Where a light is sampled from: the shading point and, on surfaces, its (shading-side) normal;
/// `n` is zero for points in a medium. Light selection may use both (a light hierarchy does).
struct LightSampleContext {
  Vec3 p;
  Vec3 n;
};

class Light {
 public:
  virtual ~Light() = default;
  /// Called once after the scene geometry is known (infinite lights need its bounds).
  virtual void preprocess(const Bounds3& scene_bounds) {}
  virtual bool sample_li(Vec3 ref_p, Vec2 u, LightSample& out) const = 0;
  /// The radiance of a sample whose li sample_li() deferred.
  virtual Rgb deferred_li(const LightSample& s) const { return s.li; }

  /// Area lights: radiance leaving the hit point `si` in direction `w` (world).
  virtual Rgb le(const SurfaceInteraction& si, Vec3 w) const { return {}; }
  /// Area lights: solid-angle pdf at `ref_p` of sampling the point `si` on this light.
  virtual float pdf_li(Vec3 ref_p, const SurfaceInteraction& si) const { return 0.f; }

  /// Infinite lights: radiance arriving along a ray that escapes the scene in direction `d`.
  virtual Rgb le_env(Vec3 d) const { return {}; }
  /// Infinite lights: solid-angle pdf of sample_li() choosing direction `d`.
  virtual float pdf_env(Vec3 d) const { return 0.f; }

  /// Emission sampling: `u_pos` picks the point (for distant lights, the point on the disk),
  /// `u_dir` the direction. False when the light emits nothing there (zero power, zero area).
  virtual bool sample_le(Vec2 u_pos, Vec2 u_dir, LightEmission& out) const { return false; }
  /// The densities sample_le() would have had for light leaving `p` (geometric normal `n`) in
  /// direction `dir` (unit, world, the direction of travel): pdf_pos per unit area, pdf_dir per
  /// unit solid angle. Distant lights ignore p and n (pdf_pos is the disk's). Zero where
  /// sample_le() cannot produce that ray; delta components report 1 as above.
  virtual void pdf_le(Vec3 p, Vec3 n, Vec3 dir, float& pdf_pos, float& pdf_dir) const {
    pdf_pos = 0.f;
    pdf_dir = 0.f;
  }

  virtual bool is_infinite() const { return false; }
  /// Emits from far away along parallel rays (sample_le's disk): infinite lights and directional.
  virtual bool is_distant() const { return is_infinite(); }
  virtual bool is_delta() const { return false; }
  /// Total emitted power (an estimate is fine); lights are picked in proportion to it.
  virtual float power() const = 0;
  /// Bytes of the tables it holds (an environment map's texels and sampling distribution).
  virtual size_t memory_bytes() const { return 0; }

  /// Light hierarchies: where and in which directions this light emits (render/light_bounds.h).
  /// False for lights that cannot say (infinite ones); those are picked with a fixed probability.
  virtual bool light_bounds(LightBounds& out) const { return false; }
  /// Area lights on triangle meshes: one light per primitive of the shape, in primitive order, to
  /// replace this one for light selection (Scene::finalize does it; Shape::prim_lights maps hits
  /// to them). Empty for lights that stay whole.
  virtual std::vector<std::unique_ptr<Light>> make_primitive_lights() const { return {}; }

  /// Position in Scene::lights, set by Scene::finalize() (per-primitive lights: their emitter's).
  uint32_t scene_index = 0;
  /// Position among the lights that light selection chooses from (LightSampler::lights()), set
  /// by Scene::finalize(); kNotSelectable for an emitter replaced by its per-primitive lights.
  static constexpr uint32_t kNotSelectable = 0xFFFFFFFFu;
  uint32_t selection_index = kNotSelectable;
};

}  // namespace tessera
