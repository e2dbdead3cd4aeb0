// A loaded scene: world-space shapes, materials, lights, camera and settings, plus the accelerator.
// Immutable after load(); shared read-only by all render threads.
#pragma once

#include "tessera/accel/bvh.h"
#include "tessera/core/sampling.h"
#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/light_sampler.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/camera.h"
#include "tessera/render/light.h"
#include "tessera/render/medium.h"
#include "tessera/render/motion.h"
#include "tessera/render/shape.h"
#include "tessera/render/texture.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

// VolPath is the path tracer that also tracks participating media; the loader turns it into Path
// on a scene without media (the same image, minus the sampler dimensions media would consume).
enum class IntegratorType { Path, VolPath, Direct };
// How path/volpath estimate direct light (integrator.h states each rule); Direct ignores it.
enum class SamplingStrategy { Mis, Bsdf, Nee };

struct IntegratorSettings {
  IntegratorType type = IntegratorType::Path;
  int max_depth = -1;       // -1: unbounded; Mitsuba counts a directly visible emitter as depth 1
  int rr_depth = 5;         // Russian roulette starts at this depth
  bool hide_emitters = false;
  bool strict_normals = false;
  // direct integrator only
  int emitter_samples = 1;
  int bsdf_samples = 1;
  // How next-event estimation picks a light (render/light_sampler.h); read by Scene::finalize.
  LightSelection light_selection = LightSelection::Bvh;
  SamplingStrategy strategy = SamplingStrategy::Mis;  // path/volpath only; not read from scene files
  /// Set by a `guided_path` integrator: the scene asks for path guiding with these settings.
  std::optional<GuidingSettings> guiding;
};

enum class SamplerType { Sobol, Independent };

struct SamplerSettings {
  SamplerType type = SamplerType::Sobol;
  int sample_count = 4;
};

class Scene {
 public:
  // Everything is owned here; objects refer to each other by raw pointer.
  std::vector<std::unique_ptr<Shape>> shapes;
  std::vector<std::shared_ptr<Bsdf>> bsdfs;
  std::vector<std::shared_ptr<Texture>> textures;
  std::vector<std::unique_ptr<Light>> lights;
  std::vector<std::shared_ptr<Medium>> media;
  const Medium* camera_medium = nullptr;  // the medium camera rays start in (null: vacuum)
  std::unique_ptr<Camera> camera;
  FilmSettings film;
  SamplerSettings sampler;
  IntegratorSettings integrator;
  // Motion blur: camera rays get a time in [shutter_open, shutter_close] (equal: no blur, all
  // rays at shutter_open). Shapes with `Shape::motion` move over it (render/motion.h).
  float shutter_open = 0.f, shutter_close = 0.f;
  bool has_shutter_interval() const { return shutter_close > shutter_open; }

  /// Builds the BVH, the primitive->shape map and the light-selection distribution; calls each
  /// light's preprocess(). Call once after every object was added.
  void finalize();

  /// Closest hit along `ray`. Surfaces with opacity (Bsdf::opacity, Mitsuba's `mask`) are passed
  /// through with probability 1 - opacity, decided by a hash of the ray (so the image stays a
  /// function of scene, pixel, sample and seed); si.t is then measured from ray.o as usual.
  /// With `stop_at_null`, surfaces with the `null` BSDF (medium boundaries) are returned instead of
  /// passed through, so the volume path tracer can switch media there.
  bool intersect(const Ray& ray, SurfaceInteraction& si, bool stop_at_null = false) const;
  /// Any hit, ignoring opacity: for callers that want geometry only (opaque scenes: the same as a
  /// shadow ray's visibility).
  bool occluded(const Ray& ray) const { return accel_.occluded(ray) || (!motion_.empty() && motion_occluded(ray)); }
  /// Fraction of light that gets along a shadow-ray segment: 0 when an opaque surface blocks it,
  /// otherwise the product of (1 - opacity) over the masked surfaces crossed.
  float transmittance(const Ray& ray) const;
  /// Transmittance along a shadow-ray segment that starts in `medium` (null: vacuum): masks as
  /// above, media attenuate, `null` surfaces switch the medium (medium_after), anything else blocks.
  Rgb transmittance(const Ray& ray, const Medium* medium) const;
  /// True when a shape bounds a medium or the camera sits in one.
  bool has_media() const { return has_media_; }
  /// True when some shape's BSDF has opacity (else intersect/transmittance take the fast path).
  bool has_masks() const { return has_masks_; }
  /// True when some shape moves (Shape::motion); else rays never look at motion instances.
  bool has_motion() const { return !motion_.empty(); }
  const std::vector<MotionInstance>& motion_instances() const { return motion_; }

  /// Picks a light to sample from the shading point `ctx` (by power, or by the light hierarchy from
  /// the point and normal: integrator.light_selection). Null (pmf 0) when the scene has none or
  /// none can reach ctx. light_pmf() is the probability that sample_light() with the same `ctx`
  /// returns `light` (for MIS of emitters hit by BSDF rays; pass si.area_light(), which for an
  /// emissive mesh is the triangle's light, not the mesh's). In a medium ctx.n is zero.
  const Light* sample_light(const LightSampleContext& ctx, float u, float& pmf) const;
  float light_pmf(const LightSampleContext& ctx, const Light* light) const;
  /// Switches the light-selection strategy after finalize() (both are built).
  void set_light_selection(LightSelection s) {
    integrator.light_selection = s;
    light_sampler_.set_strategy(s);
  }
  const LightSampler& light_sampler() const { return light_sampler_; }
  const std::vector<const Light*>& infinite_lights() const { return infinite_lights_; }

  const Bvh& accel() const { return accel_; }
  Bounds3 bounds() const { return motion_.empty() ? accel_.bounds() : merge(accel_.bounds(), motion_bounds_); }
  size_t num_triangles() const { return num_triangles_; }
  double bvh_build_seconds() const { return bvh_seconds_; }

 private:
  Bvh accel_;
  std::vector<uint32_t> prim_shape_;   // global primitive -> shape index
  std::vector<uint32_t> shape_first_;  // shape index -> first global primitive
  LightSampler light_sampler_;
  std::vector<const Light*> infinite_lights_;
  size_t num_triangles_ = 0;
  double bvh_seconds_ = 0;
  bool has_masks_ = false;
  bool has_media_ = false;
  // Moving shapes (scene_motion.cpp); their primitives are numbered from num_static_prims_ on.
  std::vector<MotionInstance> motion_;
  std::vector<uint32_t> shape_motion_;  // shape index -> motion instance (only for moving shapes)
  Bounds3 motion_bounds_;
  uint32_t num_static_prims_ = 0;

  void fill(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const;
  /// Closest hit of the static BVH and, when the scene has them, of the moving shapes.
  bool closest_hit(const Ray& ray, Hit& hit) const {
    const bool found = accel_.intersect(ray, hit);
    return motion_.empty() ? found : motion_intersect(ray, hit, found);
  }
  void build_motion(uint32_t first_prim);
  bool motion_intersect(const Ray& ray, Hit& hit, bool found) const;
  bool motion_occluded(const Ray& ray) const;
  void fill_moving(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const;
};

/// The medium a ray leaving the hit `si` in direction `w` travels in, given the one it arrived in:
/// Mitsuba's rule, interior when `w` points against the geometric normal, exterior otherwise, for
/// shapes that declare either; other shapes do not change the medium.
inline const Medium* medium_after(const SurfaceInteraction& si, Vec3 w, const Medium* current) {
  if (!si.shape || !si.shape->medium_interface) return current;
  return dot(w, si.ng) < 0.f ? si.shape->interior : si.shape->exterior;
}

}  // namespace tessera
