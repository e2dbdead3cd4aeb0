// The explicit plugin tables: Mitsuba type name -> factory. Adding a plugin = one file, one line
// here, one test. Types absent from a table are reported as unsupported by the loader.
#include "tessera/scene/load_context.h"

#include <string_view>

namespace tessera {

// Factories, one per plugin file (declared here rather than in headers: nothing else calls them).
// -- bsdfs --
// -- textures --
// -- lights --
// -- shapes --

namespace {

template <typename F>
struct Entry {
  std::string_view type;
  F factory;
};

template <typename F, size_t N>
F find(const Entry<F> (&table)[N], const std::string& type) {
  for (const auto& e : table)
    if (e.type == type) return e.factory;
  return nullptr;
}

const Entry<BsdfFactory> kBsdfs[] = {
    {"", nullptr},
};
const Entry<TextureFactory> kTextures[] = {
    {"", nullptr},
};
const Entry<LightFactory> kLights[] = {
    {"", nullptr},
};
const Entry<ShapeFactory> kShapes[] = {
    {"", nullptr},
};

}  // namespace

BsdfFactory find_bsdf_factory(const std::string& type) { return type.empty() ? nullptr : find(kBsdfs, type); }
TextureFactory find_texture_factory(const std::string& type) { return type.empty() ? nullptr : find(kTextures, type); }
LightFactory find_light_factory(const std::string& type) { return type.empty() ? nullptr : find(kLights, type); }
ShapeFactory find_shape_factory(const std::string& type) { return type.empty() ? nullptr : find(kShapes, type); }

}  // namespace tessera
