// Light selection for next-event estimation: which light to sample from a shading point, and the
// probability of that choice (which MIS needs again when a BSDF ray hits the light).
//
// Strategies (LightSelection):
// - Power: in proportion to Light::power(), from an alias table; ignores the shading point.
// - Bvh: a light hierarchy (LightBvh) over the lights that report LightBounds, descended by
//   importance at the point and normal; lights without bounds (infinite ones) get a fixed share,
//   each as much as the whole tree (as pbrt-v4).
// Both are built once; the active one can be switched at any time (set_strategy).
//
// The lights chosen from are the scene's, except that a mesh's area emitter is replaced by one
// light per triangle (Light::make_primitive_lights); build() points Shape::prim_lights at them so
// that SurfaceInteraction::area_light() returns the light that was (or would be) selected.
#pragma once

#include "tessera/core/alias_table.h"
#include "tessera/render/light_bvh.h"
#include "tessera/render/light.h"
#include "tessera/render/shape.h"

#include <memory>
#include <string>
#include <vector>

namespace tessera {

enum class LightSelection { Power, Bvh };

/// "power" / "bvh"; false for anything else.
bool parse_light_selection(const std::string& name, LightSelection& out);
const char* light_selection_name(LightSelection s);

class LightSampler {
 public:
  /// Builds the selection list, the alias table and the hierarchy; sets Light::selection_index
  /// and the shapes' prim_lights. Call once per scene, after the lights' preprocess().
  void build(const std::vector<std::unique_ptr<Light>>& lights, std::vector<std::unique_ptr<Shape>>& shapes,
             LightSelection strategy);

  LightSelection strategy() const { return strategy_; }
  void set_strategy(LightSelection s) { strategy_ = s; }

  /// A light for the point `ctx` (n = 0 in a medium) and its probability; null (pmf 0) when there
  /// is none or none can contribute there. Allocation-free, never throws.
  const Light* sample(const LightSampleContext& ctx, float u, float& pmf) const;
  /// The probability that sample(ctx, ...) returns `light` (0 for lights not chosen from).
  float pmf(const LightSampleContext& ctx, const Light* light) const;

  /// Where light subpaths start (light tracing, bidirectional methods): a light in proportion to
  /// its power whatever the strategy, and that probability; null when no light emits.
  const Light* sample_emitter(float u, float& pmf) const {
    pmf = 0.f;
    return lights_.empty() ? nullptr : lights_[power_.sample(u, &pmf)];
  }
  float emitter_pmf(const Light* light) const { return selectable(light) ? power_.pmf(light->selection_index) : 0.f; }

  /// Everything sample() can return, in selection_index order.
  const std::vector<const Light*>& lights() const { return lights_; }
  const LightBvh& bvh() const { return bvh_; }
  size_t num_primitive_lights() const { return owned_.size(); }

 private:
  std::vector<std::unique_ptr<Light>> owned_;  // per-triangle lights
  std::vector<const Light*> lights_;
  AliasTable power_;
  LightBvh bvh_;
  std::vector<const Light*> unbounded_;     // chosen with probability p_unbounded_, uniformly
  std::vector<uint8_t> is_unbounded_;       // by selection_index
  float p_unbounded_ = 0.f;
  LightSelection strategy_ = LightSelection::Bvh;

  bool selectable(const Light* light) const {
    return light && light->selection_index < lights_.size() && lights_[light->selection_index] == light;
  }
};

}  // namespace tessera
