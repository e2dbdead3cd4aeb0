// A loaded scene: shapes (world space, or object space placed by instances), materials, lights,
// camera and settings, plus the accelerators.
// Immutable after load(); shared read-only by all render threads.
#pragma once

#include "tessera/accel/bvh.h"
#include "tessera/accel/instance_bvh.h"
#include "tessera/core/sampling.h"
#include "tessera/guiding/spatial_tree.h"
#include "tessera/render/light_sampler.h"
#include "tessera/render/bsdf.h"
#include "tessera/render/camera.h"
#include "tessera/render/emission_portal.h"
#include "tessera/render/light.h"
#include "tessera/render/medium.h"
#include "tessera/render/instance.h"
#include "tessera/render/shape.h"
#include "tessera/render/texture.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

// VolPath is the path tracer that also tracks participating media; the loader turns it into Path
// on a scene without media (the same image, minus the sampler dimensions media would consume).
// Bdpt and Ptracer (bidirectional path tracing, light tracing: bdpt.h) trace surfaces only; a scene
// with media asked for them is rendered by VolPath with a note. Sppm (stochastic progressive photon
// mapping: sppm.h) and Vcm (vertex connection and merging: vcm.h) too.
enum class IntegratorType { Path, VolPath, Direct, Bdpt, Ptracer, Sppm, Vcm };
/// True for bdpt, ptracer and vcm.
inline bool is_bidirectional(IntegratorType type) {
  return type == IntegratorType::Bdpt || type == IntegratorType::Ptracer || type == IntegratorType::Vcm;
}
/// True for the integrators whose passes refine a per-pixel estimate from photons or light
/// vertices of their own pass (sppm, vcm): sequence/photon_program.h runs them.
inline bool uses_light_vertex_passes(IntegratorType type) { return type == IntegratorType::Sppm || type == IntegratorType::Vcm; }
/// "path", "volpath", "direct", "bdpt", "ptracer", "sppm", "vcm": the name scenes and --integrator use.
const char* integrator_name(IntegratorType type);
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
  // bdpt only (Mitsuba 0.6's names): lightImage, the strategies that connect light subpaths to the
  // camera (t = 1); sampleDirect, next-event estimation (s = 1). Off: left out of the estimator and
  // of its MIS weights.
  bool light_image = true;
  bool sample_direct = true;
  // bdpt, for tests and debugging (never read from files): only strategy (s, t) (bdpt.h), with
  // weight 1 or, with only_weighted, its MIS weight (the images of every strategy then sum to
  // the render's); every other strategy adds nothing. s = -1: all of them, MIS-weighted.
  int only_s = -1, only_t = -1;
  bool only_weighted = false;
  // sppm (Mitsuba 0.6's names, sppm.h): photons traced per pass; the gather radius of the first
  // pass (0: automatic, 5 scene-sphere radii over the film's larger side as Mitsuba guesses it);
  // the fraction of a pass's photons a pixel keeps (alpha); at most this many passes (-1: spp).
  // vcm (vcm.h) reads initial_radius and alpha (its radius reduction) too.
  uint64_t photon_count = 250000;
  float initial_radius = 0.f;
  float alpha = 0.7f;
  int max_passes = -1;
  // vcm: vertex merging and vertex connection (bdpt's strategies) on or off; with both, merges
  // only at vertices whose BSDF is at least merge_roughness rough (Bsdf::roughness) and, unless
  // merge_direct, not with light vertices where the light first meets a surface (direct light,
  // which next-event estimation and the connections render with less noise). vcm.h.
  bool merge = true, connect = true;
  float merge_roughness = 0.1f;
  bool merge_direct = false;
  // sppm, for tests and comparisons (never read from files): direct light at visible points from
  // photons too (photons of every length stored), as Mitsuba 0.6's sppm does, instead of
  // next-event estimation.
  bool photon_direct = false;
  // How next-event estimation picks a light (render/light_sampler.h); read by Scene::finalize.
  LightSelection light_selection = LightSelection::Bvh;
  SamplingStrategy strategy = SamplingStrategy::Mis;  // path/volpath only; not read from scene files
  /// Set by a `guided_path` integrator: the scene asks for path guiding with these settings.
  std::optional<GuidingSettings> guiding;
};

enum class SamplerType { Sobol, Independent };

/// What a loaded scene holds in memory, in bytes (Scene::memory): what a worker's scene cache
/// budgets for and reports.
struct SceneMemory {
  uint64_t accel = 0;   // BVHs: world, shapegroups, moving shapes, the top level
  uint64_t meshes = 0;  // vertex and index arrays, a mesh shared by shapes counted once
  uint64_t images = 0;  // textures' texels (shared ones once) and environment maps
  uint64_t total() const { return accel + meshes + images; }
};

struct SamplerSettings {
  SamplerType type = SamplerType::Sobol;
  int sample_count = 4;
};

class Scene {
 public:
  // Everything is owned here; objects refer to each other by raw pointer.
  std::vector<std::unique_ptr<Shape>> shapes;
  // Placements of shapegroups (render/instance.h); groups are numbered 0.. by Shape::group.
  std::vector<ShapeInstance> instances;
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
  // rays at shutter_open). Shapes with `Shape::motion` move over it (render/instance.h).
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
  bool occluded(const Ray& ray) const { return accel_.occluded(ray) || (!top_.empty() && top_.occluded(ray)); }
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
  /// True when some shape moves (Shape::motion) or some instance does.
  bool has_motion() const { return has_motion_; }
  /// Everything placed by a transform: the instances, then one per moving shape (render/instance.h).
  const InstanceBvh& instance_accel() const { return top_; }
  /// World bounds of placement `i` of instance_accel() (over the shutter when it moves).
  const Bounds3& placement_bounds(uint32_t i) const { return placements_[i].world_bounds; }

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
  /// Where distant lights' light subpaths start (render/emission_portal.h): found by finalize()
  /// for the bidirectional integrators when the scene has a distant light, else empty.
  const EmissionPortal& emission_portal() const { return emission_portal_; }

  const Bvh& accel() const { return accel_; }
  Bounds3 bounds() const { return merge(accel_.bounds(), top_.bounds()); }
  /// Triangles stored: world-space ones plus each group's and moving shape's once.
  size_t num_triangles() const { return num_triangles_; }
  /// Triangles as the camera sees them: every instance counts its group's triangles.
  uint64_t num_instanced_triangles() const { return num_instanced_triangles_; }
  /// Bytes of the BVHs: world, groups, moving shapes and the top level over instances.
  size_t accel_bytes() const;
  SceneMemory memory() const;
  double bvh_build_seconds() const { return bvh_seconds_; }

 private:
  Bvh accel_;
  std::vector<uint32_t> prim_shape_;   // world BVH primitive -> shape index
  std::vector<uint32_t> shape_first_;  // shape index -> first primitive in its BVH (world or group)
  LightSampler light_sampler_;
  std::vector<const Light*> infinite_lights_;
  EmissionPortal emission_portal_;
  size_t num_triangles_ = 0;
  double bvh_seconds_ = 0;
  bool has_masks_ = false;
  bool has_media_ = false;
  // A bit per world BVH primitive of a shape with opacity, when those are all world meshes: shadow
  // rays then cross them in one any-hit query (transmittance); otherwise empty.
  std::vector<uint64_t> see_through_;
  // Placed geometry (scene_instances.cpp): one BVH per group (moving shapes: a group each), the
  // placements and the top level over them.
  struct GroupAccel {
    Bvh bvh;
    std::vector<uint32_t> prim_shape;  // group primitive -> shape index
  };
  struct Placement {
    uint32_t group = 0;
    Transform world_from_object;                // static placements
    const AnimatedTransform* motion = nullptr;  // moving ones (owned by the instance or the shape)
    Bounds3 world_bounds;
  };
  std::vector<GroupAccel> groups_;
  std::vector<Placement> placements_;
  InstanceBvh top_;
  uint64_t num_instanced_triangles_ = 0;
  bool has_motion_ = false;

  void fill(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const;
  /// Closest hit of the world BVH and, when the scene has them, of the placed shapes.
  bool closest_hit(const Ray& ray, Hit& hit) const {
    bool found = accel_.intersect(ray, hit);
    if (top_.empty()) return found;
    Ray r = ray;
    if (found) r.tmax = hit.t;
    return top_.intersect(r, hit) || found;
  }
  void build_instances();
  void flag_see_through();
  struct MaskCrossings;  // scene.cpp: a shadow ray's product over cut-outs, as a HitFilter context
  void fill_placed(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const;
};

/// The medium a ray leaving the hit `si` in direction `w` travels in, given the one it arrived in:
/// Mitsuba's rule, interior when `w` points against the geometric normal, exterior otherwise, for
/// shapes that declare either; other shapes do not change the medium.
inline const Medium* medium_after(const SurfaceInteraction& si, Vec3 w, const Medium* current) {
  if (!si.shape || !si.shape->medium_interface) return current;
  return dot(w, si.ng) < 0.f ? si.shape->interior : si.shape->exterior;
}

}  // namespace tessera
