// What a plugin factory gets while a scene is being loaded: the node to read parameters from, and
// this context for shared resources (textures, mesh cache, paths) and for reporting.
//
// Each plugin file exports `make_<type>(const SceneNode&, LoadContext&)`; the explicit tables in
// factories.cpp map Mitsuba type names to them. A factory reads its parameters through the node's
// typed getters (which mark them used); whatever a factory did not read is reported afterwards as
// unsupported, unless it is on the list of parameters that do not change the image.
#pragma once

#include "tessera/core/rgb.h"
#include "tessera/image/image.h"
#include "tessera/render/scene.h"
#include "tessera/render/shape.h"
#include "tessera/render/texture.h"
#include "tessera/scene/error.h"
#include "tessera/scene/scene_desc.h"

#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <typeindex>
#include <typeinfo>
#include <utility>
#include <vector>

namespace tessera {

struct LoadOptions {
  bool allow_unsupported = false;
  int width = 0, height = 0;     // >0 overrides the film size
  int spp = 0;                   // >0 overrides the sampler's sample count
  std::string integrator;        // non-empty overrides the scene's integrator type
  /// Confinement of the files plugins open (meshes, images) to one directory, as
  /// ParseOptions::root_dir for the parser. Empty: SceneDesc::root_dir applies (so a description
  /// parsed confined also loads confined); both empty: unconfined.
  std::string root_dir;
};

struct LoadMessage {
  enum class Level { Note, Warning } level;
  FileLoc loc;
  std::string text;
};

class LoadContext {
 public:
  LoadContext(const SceneDesc& desc, const LoadOptions& options, Scene& scene);

  const SceneDesc& desc() const { return desc_; }
  const LoadOptions& options() const { return options_; }
  Scene& scene() { return scene_; }

  /// Resolves a file name relative to the scene's directory; throws SceneError at `loc` if the
  /// file does not exist or cannot be read, or lies outside root_dir() ("file 'X' is outside the
  /// scene bundle"; candidates outside are never looked at on disk).
  std::string resolve_path(const std::string& name, const FileLoc& loc) const;
  /// resolve_path without counting the file among resolved_files(): for look-ahead passes, which
  /// must not change which files a scene is said to need, nor their order.
  std::string locate_file(const std::string& name, const FileLoc& loc) const;
  /// The directory files must stay inside: LoadOptions::root_dir, else SceneDesc::root_dir; empty
  /// when unconfined.
  const std::string& root_dir() const {
    return options_.root_dir.empty() ? desc_.root_dir : options_.root_dir;
  }

  /// A colour parameter that may be a constant (<rgb>, <spectrum>, <float>) or a nested/referenced
  /// texture. Missing -> constant `def`. Textures are created once per node and shared.
  std::shared_ptr<Texture> texture(const SceneNode& node, const std::string& name, Rgb def);

  /// Loads a mesh file once per (path, extra key) and shares the result (object space).
  std::shared_ptr<const MeshData> cached_mesh(const std::string& key,
                                              const std::function<MeshData()>& load);

  /// Loads a resource (a decoded image, ...) once per type and key (resolved path plus whatever
  /// changes the result, e.g. gamma) and shares it: a file used by several textures is read once
  /// per scene.
  template <typename T>
  std::shared_ptr<const T> cached_resource(const std::string& key, const std::function<T()>& load) {
    auto& slot = resources_[{std::type_index(typeid(T)), key}];
    if (!slot) slot = std::make_shared<const T>(load());
    return std::static_pointer_cast<const T>(slot);
  }
  /// Stores a resource made ahead of its use (a look-ahead pass decoding files in parallel);
  /// a key already present keeps its resource.
  template <typename T>
  void add_resource(const std::string& key, std::shared_ptr<const T> resource) {
    auto& slot = resources_[{std::type_index(typeid(T)), key}];
    if (!slot) slot = std::move(resource);
  }
  template <typename T>
  bool has_resource(const std::string& key) const {
    return resources_.count({std::type_index(typeid(T)), key}) > 0;
  }
  /// The resource of type T under `key`, or null.
  template <typename T>
  std::shared_ptr<const T> find_resource(const std::string& key) const {
    auto it = resources_.find({std::type_index(typeid(T)), key});
    return it == resources_.end() ? nullptr : std::static_pointer_cast<const T>(it->second);
  }
  /// Number of distinct resources of type T loaded so far.
  template <typename T>
  size_t num_resources() const {
    size_t n = 0;
    for (const auto& entry : resources_) n += entry.first.first == std::type_index(typeid(T));
    return n;
  }
  /// True the first time `what` is asked about in this load, false after: for work done once
  /// per scene (a look-ahead pass, a warning about a shared image).
  bool first_time(const std::string& what) { return done_once_.insert(what).second; }

  /// Builds (once per node) the BSDF a shape refers to; null node -> the default diffuse BSDF.
  /// texture() and bsdf() mark the nested node consumed; a factory that uses a nested node any
  /// other way must set `node->used = true`, or the node is reported as unused.
  /// An unsupported type yields the documented fallback (diffuse 0.5 / constant texture); the
  /// final report lists it.
  const Bsdf* bsdf(const std::shared_ptr<SceneNode>& node);
  /// Builds (once per node, owned by the scene) the medium a shape or sensor refers to. Null when
  /// the type is unsupported (reported by the final walk: the medium is then ignored).
  const Medium* medium(const std::shared_ptr<SceneNode>& node);
  /// The phase function nested in (or referenced by) a medium node; isotropic when none is.
  std::shared_ptr<const PhaseFunction> phase(const SceneNode& medium_node);
  /// The singleton `null` BSDF for shapes that bound a medium without a BSDF of their own.
  const Bsdf* null_bsdf();

  void note(const FileLoc& loc, const std::string& text);
  void warn(const FileLoc& loc, const std::string& text);
  /// Records an unsupported plugin/parameter. Loading fails at the end (all items at once) unless
  /// options().allow_unsupported, in which case `fallback` is used and one warning is printed.
  void unsupported(const FileLoc& loc, const std::string& what, const std::string& fallback);

  const std::vector<LoadMessage>& messages() const { return messages_; }
  const std::vector<UnsupportedItem>& unsupported_items() const { return unsupported_; }
  /// Every path resolve_path returned, without repeats, in first-use order: the files the loaded
  /// plugins read (what a scene bundle must carry).
  const std::vector<std::string>& resolved_files() const { return resolved_files_; }

 private:
  const SceneDesc& desc_;
  LoadOptions options_;
  Scene& scene_;
  std::vector<LoadMessage> messages_;
  std::vector<UnsupportedItem> unsupported_;
  std::map<const SceneNode*, std::shared_ptr<Texture>> textures_;
  std::map<const SceneNode*, const Bsdf*> bsdfs_;
  std::map<const SceneNode*, const Medium*> media_;
  const Bsdf* null_bsdf_ = nullptr;
  std::map<std::string, std::shared_ptr<const MeshData>> meshes_;
  std::map<std::pair<std::type_index, std::string>, std::shared_ptr<const void>> resources_;
  std::set<std::string> done_once_;
  // resolve_path is const (a look-up) yet records what it found.
  mutable std::vector<std::string> resolved_files_;
  mutable std::set<std::string> resolved_set_;
};

/// A look-ahead pass: started by every LoadContext as it is made, before the build, to read a
/// plugin's resources in the background (the bitmap decoding). Keeps its work in the context
/// (add_resource), where the plugin's factory finds it; never throws.
using LookaheadPass = void (*)(LoadContext&);
/// The look-ahead passes (factories.cpp), in the order they are started.
const std::vector<LookaheadPass>& lookahead_passes();

using BsdfFactory = std::shared_ptr<Bsdf> (*)(const SceneNode&, LoadContext&);
using TextureFactory = std::shared_ptr<Texture> (*)(const SceneNode&, LoadContext&);
/// A light factory for lights that stand alone (point, constant, envmap). Area lights are made by
/// the shape loader, which knows the shape. A node that stands for more than one light (`sunsky`
/// with sunRadiusScale = 0: sky map + directional sun) adds the extra ones to ctx.scene().lights
/// itself and returns the main one.
using LightFactory = std::unique_ptr<Light> (*)(const SceneNode&, LoadContext&);
using MediumFactory = std::shared_ptr<Medium> (*)(const SceneNode&, LoadContext&);
using PhaseFactory = std::shared_ptr<PhaseFunction> (*)(const SceneNode&, LoadContext&);
/// Shape factories return object-space meshes or a sphere description; the builder applies
/// `to_world`, attaches BSDF and area light.
struct ShapeGeometry {
  std::shared_ptr<const MeshData> mesh;  // for mesh shapes (object space)
  bool is_sphere = false;
  Vec3 center;                           // sphere, object space
  float radius = 1.f;
  bool face_normals = false;
  bool flip_normals = false;
};
using ShapeFactory = ShapeGeometry (*)(const SceneNode&, LoadContext&);

/// The `area` emitter nested in a shape (light/area.cpp); `shape` is the world-space shape it
/// emits from. The caller attaches the result (shape.light) and moves it into scene.lights.
std::unique_ptr<Light> make_area_light(const SceneNode& emitter, LoadContext& ctx, const Shape& shape);

/// Factory tables (factories.cpp); nullptr when the type is not supported.
BsdfFactory find_bsdf_factory(const std::string& type);
TextureFactory find_texture_factory(const std::string& type);
LightFactory find_light_factory(const std::string& type);
MediumFactory find_medium_factory(const std::string& type);
PhaseFactory find_phase_factory(const std::string& type);
ShapeFactory find_shape_factory(const std::string& type);
/// Plugin types of one factory table ("bsdf", "texture", "shape", "emitter", "medium", "phase"), in
/// table order.
std::vector<std::string> registered_plugins(const std::string& tag);

struct LoadResult {
  std::unique_ptr<Scene> scene;
  std::vector<LoadMessage> messages;
  std::vector<UnsupportedItem> unsupported;  // non-empty only with allow_unsupported
  /// Every file the loader opened (LoadContext::resolved_files): with SceneDesc's file,
  /// included_files and spectrum_files, what the scene needs (farm/bundle.h scene_files()).
  std::vector<std::string> files;
};

/// Parsed description -> renderable scene (meshes and images loaded, BVH built). Throws SceneError,
/// or UnsupportedError listing every unsupported item when !allow_unsupported.
LoadResult load_scene(const SceneDesc& desc, const LoadOptions& options);

}  // namespace tessera
