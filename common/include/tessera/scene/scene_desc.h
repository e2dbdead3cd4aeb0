// The parsed form of a Mitsuba XML scene: a tree of plugin nodes with typed properties, every one
// carrying its file and line. Parsing (this file's producer, xml_parser) reads no meshes or images;
// loading (scene_builder) turns nodes into renderer objects and marks what it consumed, so that
// anything left unconsumed can be reported as unsupported.
#pragma once

#include "tessera/core/animated_transform.h"
#include "tessera/core/rgb.h"
#include "tessera/core/transform.h"
#include "tessera/core/vec.h"
#include "tessera/scene/error.h"

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace tessera {

// Animation: Mitsuba 0.6's <animation name=..> of <transform time=..> keyframes (motion blur).
enum class PropType { Boolean, Integer, Float, String, Color, Vector, Transform, Animation };

/// One `<float name=.. value=..>`-like entry. Names are normalised to Mitsuba 3's snake_case
/// (`toWorld` -> `to_world`, `maxDepth` -> `max_depth`); `written_name` keeps the spelling used.
struct Property {
  std::string name;
  std::string written_name;
  PropType type = PropType::Float;
  FileLoc loc;
  bool b = false;
  int64_t i = 0;
  double f = 0;
  std::string s;
  Rgb color;       // <rgb>, <srgb> (linearised), <spectrum> (reduced to RGB), <blackbody>
  Vec3 v;          // <point>, <vector>
  tessera::Transform xf;  // for an Animation: its first keyframe
  std::vector<AnimatedTransform::Keyframe> keyframes;  // Animation only: strictly increasing times
  mutable bool used = false;
};

struct SceneNode {
  std::string tag;   // scene, shape, bsdf, emitter, sensor, film, sampler, rfilter, integrator,
                     // texture, medium, phase, subsurface, shapegroup, ...
  std::string type;  // plugin type, e.g. "diffuse"
  std::string id;    // `id` attribute, empty if none
  std::string name;  // `name` attribute of a nested object, e.g. a texture bound to "reflectance"
  FileLoc loc;
  std::vector<Property> props;
  /// Nested objects in document order. A <ref id=..> appears here as the referenced node itself
  /// (shared), with `ref_names` giving the `name` attribute the ref used, if any.
  std::vector<std::shared_ptr<SceneNode>> children;
  std::vector<std::string> child_names;  // parallel to children: name attribute of nested obj/ref
  mutable bool used = false;

  // Typed look-ups; they mark the property used. A present property of the wrong type throws
  // SceneError naming file, line and property.
  const Property* find(const std::string& name) const;
  /// find() for messages: not logged as a parameter the plugin reads (scene/parameter_log.h).
  const Property* peek(const std::string& name) const;
  bool has(const std::string& name) const { return find(name) != nullptr; }
  /// Where parameter `name` was written (the node's own location when absent), for errors.
  FileLoc loc_of(const std::string& name) const {
    const Property* p = peek(name);
    return p ? p->loc : loc;
  }
  float get_float(const std::string& name, float def) const;
  int64_t get_int(const std::string& name, int64_t def) const;
  bool get_bool(const std::string& name, bool def) const;
  std::string get_string(const std::string& name, const std::string& def) const;
  Rgb get_color(const std::string& name, Rgb def) const;  // accepts a float as grey
  Vec3 get_vector(const std::string& name, Vec3 def) const;
  /// An <animation> here is an error naming the node: only plugins that call
  /// get_animated_transform() support moving.
  tessera::Transform get_transform(const std::string& name, const tessera::Transform& def) const;
  /// A <transform> (static) or an <animation> (keyframes).
  AnimatedTransform get_animated_transform(const std::string& name, const tessera::Transform& def) const;

  /// Children with the given tag, in document order.
  std::vector<std::shared_ptr<SceneNode>> children_with_tag(const std::string& tag) const;
  /// The nested object or ref bound to parameter `name` (e.g. <texture name="reflectance">).
  std::shared_ptr<SceneNode> named_child(const std::string& name) const;

  /// "bsdf 'diffuse'" / "bsdf 'diffuse' (id 'Floor')": for messages.
  std::string describe() const;
};

struct SceneDesc {
  std::shared_ptr<SceneNode> root;  // tag "scene"
  int version_major = 0;            // 0 for 0.5/0.6, 2 or 3 for the newer syntax
  std::string version;              // as written
  std::string file;                 // path of the top-level XML
  std::string base_dir;             // directory relative file names resolve against
  /// Files the parser read besides `file` (for bundling a scene), as opened, in reading order:
  /// each <include>d XML, and each <spectrum filename=..> data file.
  std::vector<std::string> included_files;
  std::vector<std::string> spectrum_files;
  /// ParseOptions::root_dir as parsed: load_scene confines the files it opens to it too, unless
  /// LoadOptions::root_dir names another root. Empty: unconfined.
  std::string root_dir;
};

struct ParseOptions {
  std::map<std::string, std::string> defines;  // -D name=value, override <default>
  /// Confinement (farm bundles): when non-empty, every file the parser opens (the scene file,
  /// <include>s, <spectrum filename=..>) must lie inside this directory, both lexically and with
  /// symlinks resolved; any other is refused with SceneError "file 'X' is outside the scene
  /// bundle" at the element naming it, before it is opened. Empty: unconfined (`../textures` works).
  std::string root_dir;
};

/// Reads a Mitsuba XML scene (includes followed). Throws SceneError with file and line.
SceneDesc parse_scene_file(const std::string& path, const ParseOptions& options = {});
/// Same, from a string; `virtual_path` names it in messages and sets base_dir.
SceneDesc parse_scene_string(const std::string& xml, const std::string& virtual_path,
                             const ParseOptions& options = {});

}  // namespace tessera
