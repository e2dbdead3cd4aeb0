#include "tessera/bsdf/microfacet_params.h"

#include <string>

namespace tessera {

MicrofacetType read_microfacet_type(const SceneNode& node, LoadContext& ctx) {
  // Visible-normal sampling changes only the variance; GGX always uses it, Beckmann/Phong never.
  (void)node.get_bool("sample_visible", true);
  const std::string name = node.get_string("distribution", "beckmann");
  if (std::optional<MicrofacetType> type = parse_microfacet_type(name)) return *type;
  const Property* p = node.find("distribution");
  const FileLoc loc = p ? p->loc : node.loc;
  if (name == "as") {
    ctx.unsupported(loc, node.describe() + " distribution 'as'", "beckmann");
    return MicrofacetType::Beckmann;
  }
  throw SceneError(loc, "unknown microfacet distribution '" + name + "' for " + node.describe() +
                            "; expected beckmann, ggx or phong");
}

MicrofacetAlpha read_microfacet_alpha(const SceneNode& node, LoadContext& ctx) {
  auto given = [&](const std::string& name) { return node.find(name) != nullptr || node.named_child(name) != nullptr; };
  std::shared_ptr<Texture> alpha = ctx.texture(node, "alpha", Rgb(0.1f));
  return {given("alpha_u") ? ctx.texture(node, "alpha_u", Rgb(0.1f)) : alpha,
          given("alpha_v") ? ctx.texture(node, "alpha_v", Rgb(0.1f)) : alpha};
}

}  // namespace tessera
