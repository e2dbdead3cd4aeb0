#include "tessera/render/aov.h"

#include <sstream>

namespace tessera {

void add_aov_sums(AovSums& d, const AovSums& s) {
  for (int c = 0; c < 3; ++c) {
    d.albedo[c] += s.albedo[c];
    d.normal[c] += s.normal[c];
    d.half_sum[c] += s.half_sum[c];
  }
  d.depth += s.depth;
  d.half_count += s.half_count;
}

const char* aov_layer_name(AovLayer layer) {
  switch (layer) {
    case AovLayer::Albedo: return "albedo";
    case AovLayer::Normal: return "normal";
    case AovLayer::Depth: return "depth";
    case AovLayer::Variance: return "variance";
    case AovLayer::HalfA: return "half_a";
    case AovLayer::HalfB: break;
  }
  return "half_b";
}

std::vector<std::string> aov_channel_names(AovLayer layer) {
  switch (layer) {
    case AovLayer::Normal: return {"X", "Y", "Z"};
    case AovLayer::Depth: return {"Z"};
    default: break;
  }
  return {"R", "G", "B"};
}

std::optional<std::vector<AovLayer>> parse_aov_layers(const std::string& list, std::string* error) {
  std::vector<AovLayer> layers;
  std::stringstream in(list);
  std::string name;
  bool any = false;
  while (std::getline(in, name, ',')) {
    any = true;
    bool known = false;
    for (int i = 0; i < kAovLayerCount; ++i) {
      const AovLayer layer = AovLayer(i);
      if (name != "all" && name != aov_layer_name(layer)) continue;
      known = true;
      bool listed = false;
      for (AovLayer l : layers) listed |= l == layer;
      if (!listed) layers.push_back(layer);
    }
    if (!known) {
      if (error)
        *error = "unknown AOV '" + name + "' (known: albedo, normal, depth, variance, half_a, half_b, all)";
      return std::nullopt;
    }
  }
  if (!any) {
    if (error) *error = "empty AOV list";
    return std::nullopt;
  }
  return layers;
}

}  // namespace tessera
