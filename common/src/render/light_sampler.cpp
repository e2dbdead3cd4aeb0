// LightSampler: the selection list (emitters, meshes split per triangle) and the two strategies.
// sample() and pmf() compute every probability with the same expressions in the same order, so a
// light's pmf equals the pmf sample() returned for it bit for bit (MIS relies on the equality, the
// tests check it).
#include "tessera/render/light_sampler.h"

#include "tessera/render/light_bounds.h"

#include <algorithm>

namespace tessera {

bool parse_light_selection(const std::string& name, LightSelection& out) {
  if (name == "power") out = LightSelection::Power;
  else if (name == "bvh") out = LightSelection::Bvh;
  else return false;
  return true;
}

const char* light_selection_name(LightSelection s) { return s == LightSelection::Power ? "power" : "bvh"; }

void LightSampler::build(const std::vector<std::unique_ptr<Light>>& lights,
                         std::vector<std::unique_ptr<Shape>>& shapes, LightSelection strategy) {
  strategy_ = strategy;
  owned_.clear();
  lights_.clear();
  unbounded_.clear();
  // Split the emitters of meshes; a split emitter is not itself chosen from.
  std::vector<uint8_t> split(lights.size(), 0);
  for (auto& shape : shapes) {
    shape->prim_lights.clear();
    const Light* light = shape->light;
    if (!light || light->scene_index >= lights.size() || lights[light->scene_index].get() != light) continue;
    auto prims = light->make_primitive_lights();
    if (prims.empty() || prims.size() != shape->num_primitives()) continue;
    split[light->scene_index] = 1;
    shape->prim_lights.reserve(prims.size());
    for (auto& p : prims) {
      p->scene_index = light->scene_index;
      shape->prim_lights.push_back(p.get());
      owned_.push_back(std::move(p));
    }
  }
  std::vector<Light*> list;
  list.reserve(lights.size() + owned_.size());
  for (size_t i = 0; i < lights.size(); ++i) {
    lights[i]->selection_index = Light::kNotSelectable;
    if (!split[i]) list.push_back(lights[i].get());
  }
  for (const auto& p : owned_) list.push_back(p.get());
  lights_.assign(list.begin(), list.end());

  std::vector<float> power(lights_.size());
  std::vector<LightBounds> bounds(lights_.size());
  is_unbounded_.assign(lights_.size(), 0);
  for (uint32_t i = 0; i < lights_.size(); ++i) {
    Light& l = *list[i];
    l.selection_index = i;
    power[i] = std::max(l.power(), 0.f);
    LightBounds b;
    if (l.is_infinite() || !l.light_bounds(b)) {
      // Only lights that emit something are worth a fixed share.
      if (power[i] > 0.f || l.is_infinite()) {
        unbounded_.push_back(&l);
        is_unbounded_[i] = 1;
      }
      b = LightBounds();
    }
    bounds[i] = b;
  }
  power_ = AliasTable(power);
  bvh_ = LightBvh(bounds);
  const size_t shares = unbounded_.size() + (bvh_.empty() ? 0 : 1);
  p_unbounded_ = shares ? float(unbounded_.size()) / float(shares) : 0.f;
}

const Light* LightSampler::sample(const LightSampleContext& ctx, float u, float& pmf) const {
  pmf = 0.f;
  if (lights_.empty()) return nullptr;
  if (strategy_ == LightSelection::Power) {
    uint32_t i = power_.sample(u, &pmf);
    return lights_[i];
  }
  if (u < p_unbounded_) {
    const size_t n = unbounded_.size();
    const size_t i = std::min(size_t(u / p_unbounded_ * float(n)), n - 1);
    pmf = p_unbounded_ / float(n);
    return unbounded_[i];
  }
  u = std::min((u - p_unbounded_) / (1.f - p_unbounded_), 0x1.fffffep-1f);
  float pmf_tree = 0.f;
  const uint32_t i = bvh_.sample(ctx.p, ctx.n, u, pmf_tree);
  if (i == LightBvh::kNone) return nullptr;
  pmf = (1.f - p_unbounded_) * pmf_tree;
  return lights_[i];
}

float LightSampler::pmf(const LightSampleContext& ctx, const Light* light) const {
  if (!selectable(light)) return 0.f;
  const uint32_t i = light->selection_index;
  if (strategy_ == LightSelection::Power) return power_.pmf(i);
  if (is_unbounded_[i]) return p_unbounded_ / float(unbounded_.size());
  return (1.f - p_unbounded_) * bvh_.pmf(ctx.p, ctx.n, i);
}

}  // namespace tessera
