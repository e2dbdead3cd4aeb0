// The explicit plugin tables: Mitsuba type name -> factory. Adding a plugin = one file, one line
// here, one test. Types absent from a table are reported as unsupported by the loader.
#include "tessera/scene/load_context.h"

#include <string_view>

namespace tessera {

// Factories, one per plugin file (declared here rather than in headers: nothing else calls them).
// -- bsdfs --
std::shared_ptr<Bsdf> make_diffuse(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_roughdiffuse(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_phong(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_twosided(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_conductor(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_roughconductor(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_dielectric(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_roughdielectric(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_thindielectric(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_plastic(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_roughplastic(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_bumpmap(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_normalmap(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_blendbsdf(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_coating(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_roughcoating(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_mask(const SceneNode&, LoadContext&);
std::shared_ptr<Bsdf> make_null(const SceneNode&, LoadContext&);
// -- textures --
std::shared_ptr<Texture> make_bitmap(const SceneNode&, LoadContext&);
std::shared_ptr<Texture> make_checkerboard(const SceneNode&, LoadContext&);
std::shared_ptr<Texture> make_scale(const SceneNode&, LoadContext&);
// -- look-ahead passes --
void prefetch_bitmaps(LoadContext&);
// -- lights --
std::unique_ptr<Light> make_point(const SceneNode&, LoadContext&);
std::unique_ptr<Light> make_spot(const SceneNode&, LoadContext&);
std::unique_ptr<Light> make_envmap(const SceneNode&, LoadContext&);
std::unique_ptr<Light> make_constant(const SceneNode&, LoadContext&);
std::unique_ptr<Light> make_directional(const SceneNode&, LoadContext&);
std::unique_ptr<Light> make_sunsky(const SceneNode&, LoadContext&);
std::unique_ptr<Light> make_sky(const SceneNode&, LoadContext&);
std::unique_ptr<Light> make_sun(const SceneNode&, LoadContext&);
// -- media and phase functions --
std::shared_ptr<Medium> make_homogeneous(const SceneNode&, LoadContext&);
std::shared_ptr<PhaseFunction> make_isotropic(const SceneNode&, LoadContext&);
std::shared_ptr<PhaseFunction> make_hg(const SceneNode&, LoadContext&);
// -- shapes --
ShapeGeometry make_obj(const SceneNode&, LoadContext&);
ShapeGeometry make_ply(const SceneNode&, LoadContext&);
ShapeGeometry make_serialized(const SceneNode&, LoadContext&);
ShapeGeometry make_rectangle(const SceneNode&, LoadContext&);
ShapeGeometry make_cube(const SceneNode&, LoadContext&);
ShapeGeometry make_disk(const SceneNode&, LoadContext&);
ShapeGeometry make_sphere(const SceneNode&, LoadContext&);

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
    {"diffuse", make_diffuse},
    {"roughdiffuse", make_roughdiffuse},
    {"phong", make_phong},
    {"twosided", make_twosided},
    {"conductor", make_conductor},
    {"roughconductor", make_roughconductor},
    {"dielectric", make_dielectric},
    {"roughdielectric", make_roughdielectric},
    {"thindielectric", make_thindielectric},
    {"plastic", make_plastic},
    {"roughplastic", make_roughplastic},
    {"bumpmap", make_bumpmap},
    {"normalmap", make_normalmap},
    {"blendbsdf", make_blendbsdf},
    {"coating", make_coating},
    {"roughcoating", make_roughcoating},
    {"mask", make_mask},
    {"null", make_null},
    {"", nullptr},
};
const Entry<TextureFactory> kTextures[] = {
    {"bitmap", make_bitmap},
    {"checkerboard", make_checkerboard},
    {"scale", make_scale},
    {"", nullptr},
};
const Entry<LightFactory> kLights[] = {
    {"point", make_point},
    {"spot", make_spot},
    {"envmap", make_envmap},
    {"constant", make_constant},
    {"directional", make_directional},
    {"sunsky", make_sunsky},
    {"sky", make_sky},
    {"sun", make_sun},
    {"", nullptr},
};
const Entry<MediumFactory> kMedia[] = {
    {"homogeneous", make_homogeneous},
    {"", nullptr},
};
const Entry<PhaseFactory> kPhases[] = {
    {"isotropic", make_isotropic},
    {"hg", make_hg},
    {"", nullptr},
};
const Entry<ShapeFactory> kShapes[] = {
    {"obj", make_obj},
    {"ply", make_ply},
    {"serialized", make_serialized},
    {"rectangle", make_rectangle},
    {"cube", make_cube},
    {"disk", make_disk},
    {"sphere", make_sphere},
    {"", nullptr},
};

template <typename F, size_t N>
std::vector<std::string> names(const Entry<F> (&table)[N]) {
  std::vector<std::string> out;
  for (const auto& e : table)
    if (!e.type.empty()) out.emplace_back(e.type);
  return out;
}

}  // namespace

std::vector<std::string> registered_plugins(const std::string& tag) {
  if (tag == "bsdf") return names(kBsdfs);
  if (tag == "texture") return names(kTextures);
  if (tag == "shape") return names(kShapes);
  if (tag == "medium") return names(kMedia);
  if (tag == "phase") return names(kPhases);
  if (tag == "emitter") {
    auto out = names(kLights);
    out.push_back("area");  // made by the shape loader, not a table entry
    return out;
  }
  return {};
}

const std::vector<LookaheadPass>& lookahead_passes() {
  static const std::vector<LookaheadPass> passes = {prefetch_bitmaps};
  return passes;
}

BsdfFactory find_bsdf_factory(const std::string& type) { return type.empty() ? nullptr : find(kBsdfs, type); }
TextureFactory find_texture_factory(const std::string& type) { return type.empty() ? nullptr : find(kTextures, type); }
LightFactory find_light_factory(const std::string& type) { return type.empty() ? nullptr : find(kLights, type); }
MediumFactory find_medium_factory(const std::string& type) { return type.empty() ? nullptr : find(kMedia, type); }
PhaseFactory find_phase_factory(const std::string& type) { return type.empty() ? nullptr : find(kPhases, type); }
ShapeFactory find_shape_factory(const std::string& type) { return type.empty() ? nullptr : find(kShapes, type); }

}  // namespace tessera
