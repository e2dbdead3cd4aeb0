// A loaded scene: world-space shapes, materials, lights, camera and settings, plus the accelerator.
// Immutable after load(); shared read-only by all render threads.
#pragma once

#include "tessera/accel/bvh.h"
#include "tessera/core/sampling.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/camera.h"
#include "tessera/render/light.h"
#include "tessera/render/shape.h"
#include "tessera/render/texture.h"

#include <memory>
#include <string>
#include <vector>

namespace tessera {

enum class IntegratorType { Path, Direct };

struct IntegratorSettings {
  IntegratorType type = IntegratorType::Path;
  int max_depth = -1;       // -1: unbounded; Mitsuba counts a directly visible emitter as depth 1
  int rr_depth = 5;         // Russian roulette starts at this depth
  bool hide_emitters = false;
  bool strict_normals = false;
  // direct integrator only
  int emitter_samples = 1;
  int bsdf_samples = 1;
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
  std::unique_ptr<Camera> camera;
  FilmSettings film;
  SamplerSettings sampler;
  IntegratorSettings integrator;

  /// Builds the BVH, the primitive->shape map and the light-selection distribution; calls each
  /// light's preprocess(). Call once after every object was added.
  void finalize();

  /// Closest hit along `ray`. Surfaces with opacity (Bsdf::opacity, Mitsuba's `mask`) are passed
  /// through with probability 1 - opacity, decided by a hash of the ray (so the image stays a
  /// function of scene, pixel, sample and seed); si.t is then measured from ray.o as usual.
  bool intersect(const Ray& ray, SurfaceInteraction& si) const;
  /// Any hit, ignoring opacity: for callers that want geometry only (opaque scenes: the same as a
  /// shadow ray's visibility).
  bool occluded(const Ray& ray) const { return accel_.occluded(ray); }
  /// Fraction of light that gets along a shadow-ray segment: 0 when an opaque surface blocks it,
  /// otherwise the product of (1 - opacity) over the masked surfaces crossed.
  float transmittance(const Ray& ray) const;
  /// True when some shape's BSDF has opacity (else intersect/transmittance take the fast path).
  bool has_masks() const { return has_masks_; }

  /// Picks a light to sample from the shading point `ctx` (by power; a light hierarchy may use the
  /// point and normal). Null when the scene has none. light_pmf() is the probability that
  /// sample_light() with the same `ctx` returns `light` (for MIS of emitters hit by BSDF rays).
  const Light* sample_light(const LightSampleContext& ctx, float u, float& pmf) const;
  float light_pmf(const LightSampleContext& ctx, const Light* light) const;
  const std::vector<const Light*>& infinite_lights() const { return infinite_lights_; }

  const Bvh& accel() const { return accel_; }
  Bounds3 bounds() const { return accel_.bounds(); }
  size_t num_triangles() const { return num_triangles_; }
  double bvh_build_seconds() const { return bvh_seconds_; }

 private:
  Bvh accel_;
  std::vector<uint32_t> prim_shape_;   // global primitive -> shape index
  std::vector<uint32_t> shape_first_;  // shape index -> first global primitive
  Distribution1D light_distr_;
  std::vector<const Light*> infinite_lights_;
  size_t num_triangles_ = 0;
  double bvh_seconds_ = 0;
  bool has_masks_ = false;

  void fill(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const;
};

}  // namespace tessera
