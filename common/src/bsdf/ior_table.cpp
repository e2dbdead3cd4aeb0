#include "tessera/bsdf/ior.h"

#include "tessera/core/check.h"
#include "tessera/scene/error.h"
#include "tessera/scene/scene_desc.h"

#include <algorithm>
#include <cctype>

namespace tessera {
namespace {

struct IorEntry {
  std::string_view name;
  float value;
};

// Mitsuba 0.6 src/bsdfs/ior.h, same order and values (scenes written for it expect these exactly).
constexpr IorEntry kIorTable[] = {
    {"vacuum", 1.0f},
    {"helium", 1.000036f},
    {"hydrogen", 1.000132f},
    {"air", 1.000277f},
    {"carbon dioxide", 1.00045f},
    {"water", 1.3330f},
    {"acetone", 1.36f},
    {"ethanol", 1.361f},
    {"carbon tetrachloride", 1.461f},
    {"glycerol", 1.4729f},
    {"benzene", 1.501f},
    {"silicone oil", 1.52045f},
    {"bromine", 1.661f},
    {"water ice", 1.31f},
    {"fused quartz", 1.458f},
    {"pyrex", 1.470f},
    {"acrylic glass", 1.49f},
    {"polypropylene", 1.49f},
    {"bk7", 1.5046f},
    {"sodium chloride", 1.544f},
    {"amber", 1.55f},
    {"pet", 1.5750f},
    {"diamond", 2.419f},
};

}  // namespace

std::optional<float> lookup_ior(std::string_view name) {
  std::string lower(name);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  for (const IorEntry& e : kIorTable)
    if (e.name == lower) return e.value;
  return std::nullopt;
}

std::string known_ior_names() {
  std::string out;
  for (const IorEntry& e : kIorTable) {
    if (!out.empty()) out += ", ";
    out += e.name;
  }
  return out;
}

float read_ior(const SceneNode& node, const std::string& name, std::string_view default_name) {
  const Property* p = node.find(name);
  if (p && p->type == PropType::String) {
    p->used = true;
    if (auto v = lookup_ior(p->s)) return *v;
    throw SceneError(p->loc, "unknown IOR name '" + p->s + "' for parameter '" + p->written_name + "' of " +
                                 node.describe() + "; known names: " + known_ior_names());
  }
  if (p) return node.get_float(name, 1.f);  // numeric (or a type error reported by get_float)
  auto def = lookup_ior(default_name);
  TESSERA_CHECK(def.has_value());
  return *def;
}

}  // namespace tessera
