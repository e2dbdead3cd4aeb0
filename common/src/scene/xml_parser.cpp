// Mitsuba XML -> SceneDesc. One pass over each document in order, as Mitsuba does: `$name`
// substitution in every attribute, <default> before use, ids defined before their <ref>, and
// <include>d files spliced in place. Value grammar lives in xml_values.cpp.
#include "tessera/scene/scene_desc.h"

#include "scene/path_confinement.h"
#include "scene/xml_values.h"

#include <pugixml.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

namespace tessera {

namespace {

namespace fs = std::filesystem;
using xml::Attrs;

constexpr int kMaxDepth = 64;         // nesting of elements; deeper input is certainly broken
constexpr int kMaxIncludeDepth = 32;  // nested <include>s

bool is_object_tag(std::string_view t) {
  static const std::set<std::string_view> tags = {
      "bsdf",       "texture", "shape",  "emitter",    "sensor", "film",     "sampler", "rfilter",
      "integrator", "medium",  "phase",  "subsurface", "volume", "spectrum", "shapegroup"};
  return tags.count(t) > 0;
}

bool is_property_tag(std::string_view t) {
  static const std::set<std::string_view> tags = {"boolean", "integer", "float",     "string",
                                                  "rgb",     "srgb",    "spectrum",  "blackbody",
                                                  "point",   "vector",  "transform"};
  return tags.count(t) > 0;
}

std::string squote(std::string_view s) { return "'" + std::string(s) + "'"; }

/// One XML document being read: the main file or an included one.
struct Source {
  std::string path;   // as shown in messages (the user's spelling, or derived from it for includes)
  std::string dir;    // directory of `path`, for relative includes
  std::string text;
  std::vector<size_t> line_starts;
  pugi::xml_document doc;
  int version_major = 0;

  int line_of(ptrdiff_t offset) const {
    if (offset < 0) return 0;
    auto it = std::upper_bound(line_starts.begin(), line_starts.end(), size_t(offset));
    return int(it - line_starts.begin());
  }
  FileLoc loc(const pugi::xml_node& n) const { return {path, line_of(n.offset_debug())}; }
};

std::pair<std::string, int> parse_version(const std::string& v, const FileLoc& loc) {
  std::vector<int> parts;
  std::string cur;
  for (char c : v + ".") {
    if (c == '.') {
      if (cur.empty() || cur.size() > 4) throw SceneError(loc, "invalid scene version " + squote(v));
      parts.push_back(std::stoi(cur));
      cur.clear();
    } else if (std::isdigit(static_cast<unsigned char>(c))) {
      cur += c;
    } else {
      throw SceneError(loc, "invalid scene version " + squote(v));
    }
  }
  if (parts.size() < 2 || parts.size() > 3) throw SceneError(loc, "invalid scene version " + squote(v));
  return {v, parts[0]};
}

class Parser {
 public:
  explicit Parser(const ParseOptions& options) : params_(options.defines), root_dir_(options.root_dir) {}

  SceneDesc run(std::string text, const std::string& path) {
    Source src;
    src.path = path;
    src.dir = fs::path(path).parent_path().string();
    src.text = std::move(text);
    base_dir_ = src.dir;
    std::error_code ec;
    include_stack_.push_back(fs::weakly_canonical(fs::path(path), ec).string());

    pugi::xml_node root = load_document(src, std::nullopt);
    SceneDesc desc;
    desc.file = path;
    desc.base_dir = base_dir_;
    desc.version = root.attribute("version").value();
    desc.version_major = src.version_major;
    desc.root = std::make_shared<SceneNode>();
    desc.root->tag = "scene";
    desc.root->loc = src.loc(root);
    parse_children(src, root, *desc.root, 1);
    desc.included_files = std::move(included_files_);
    desc.spectrum_files = std::move(spectrum_files_);
    desc.root_dir = root_dir_;
    return desc;
  }

 private:
  std::map<std::string, std::string> params_;  // -D first; <default> only fills gaps
  std::map<std::string, std::shared_ptr<SceneNode>> ids_;
  std::vector<std::string> include_stack_;     // canonical paths, for cycle detection
  std::string base_dir_;
  std::string root_dir_;                       // ParseOptions::root_dir; empty: unconfined
  std::vector<std::string> included_files_;    // as opened, for SceneDesc
  std::vector<std::string> spectrum_files_;

  /// Parses `src.text`, checks the <scene> root and its version; returns the root element.
  pugi::xml_node load_document(Source& src, std::optional<int> inherited_version) {
    src.line_starts.push_back(0);
    for (size_t i = 0; i < src.text.size(); ++i)
      if (src.text[i] == '\n') src.line_starts.push_back(i + 1);
    pugi::xml_parse_result r = src.doc.load_buffer(src.text.data(), src.text.size(), pugi::parse_default);
    if (!r)
      throw SceneError(FileLoc{src.path, src.line_of(r.offset)},
                       std::string("malformed XML: ") + r.description());
    pugi::xml_node root;
    for (pugi::xml_node n : src.doc.children()) {
      if (n.type() != pugi::node_element) continue;
      if (root) throw SceneError(src.loc(n), "more than one top-level element");
      root = n;
    }
    if (!root) throw SceneError(FileLoc{src.path, 1}, "no <scene> element");
    if (std::string_view(root.name()) != "scene")
      throw SceneError(src.loc(root), "the top-level element must be <scene>, not <" +
                                          std::string(root.name()) + ">");
    for (pugi::xml_attribute a : root.attributes()) {
      std::string_view n = a.name();
      if (n != "version" && n.substr(0, 5) != "xmlns" && n.substr(0, 4) != "xsi:")
        throw SceneError(src.loc(root), "unexpected attribute " + squote(n) + " in <scene>");
    }
    pugi::xml_attribute version = root.attribute("version");
    if (version)
      src.version_major = parse_version(version.value(), src.loc(root)).second;
    else if (inherited_version)
      src.version_major = *inherited_version;
    else
      throw SceneError(src.loc(root), "<scene> needs a version attribute (e.g. version=\"0.6.0\" or \"3.0.0\")");
    return root;
  }

  std::string substitute(const std::string& value, const FileLoc& loc) const {
    if (value.find('$') == std::string::npos) return value;
    std::string out;
    for (size_t i = 0; i < value.size();) {
      if (value[i] != '$') {
        out += value[i++];
        continue;
      }
      // The longest defined name wins, as Mitsuba substitutes longer names first.
      const std::string* best_key = nullptr;
      const std::string* best_value = nullptr;
      for (const auto& [k, v] : params_)
        if (!k.empty() && value.compare(i + 1, k.size(), k) == 0 && (!best_key || k.size() > best_key->size())) {
          best_key = &k;
          best_value = &v;
        }
      if (best_key) {
        out += *best_value;
        i += 1 + best_key->size();
        continue;
      }
      size_t j = i + 1;
      while (j < value.size() && (std::isalnum(static_cast<unsigned char>(value[j])) || value[j] == '_')) ++j;
      if (j > i + 1)
        throw SceneError(loc, "undefined parameter '$" + value.substr(i + 1, j - i - 1) +
                                  "' (declare it with <default> or pass -D " + value.substr(i + 1, j - i - 1) +
                                  "=...)");
      out += value[i++];
    }
    return out;
  }

  Attrs attrs_of(const Source& src, const pugi::xml_node& el) const {
    Attrs a;
    FileLoc loc = src.loc(el);
    for (pugi::xml_attribute at : el.attributes()) {
      if (a.get(at.name())) throw SceneError(loc, "attribute " + squote(at.name()) + " given twice");
      a.items.emplace_back(at.name(), substitute(at.value(), loc));
    }
    return a;
  }

  void parse_children(Source& src, const pugi::xml_node& xml_parent, SceneNode& parent, int depth) {
    if (depth > kMaxDepth) throw SceneError(src.loc(xml_parent), "elements nested too deeply");
    for (pugi::xml_node el : xml_parent.children()) {
      if (el.type() != pugi::node_element) continue;  // comments and stray text are ignored
      parse_element(src, el, parent, depth);
    }
  }

  void parse_element(Source& src, const pugi::xml_node& el, SceneNode& parent, int depth) {
    const std::string tag = el.name();
    const FileLoc loc = src.loc(el);
    Attrs attrs = attrs_of(src, el);
    const bool at_scene_level = parent.tag == "scene";

    if (tag == "default") {
      if (!at_scene_level) throw SceneError(loc, "<default> must be a direct child of <scene>");
      attrs.check_allowed({"name", "value"}, tag, loc);
      const std::string& name = attrs.require("name", tag, loc);
      if (name.empty()) throw SceneError(loc, "<default> needs a non-empty name");
      params_.emplace(name, attrs.require("value", tag, loc));  // keeps -D and earlier defaults
      return;
    }
    if (tag == "include") {
      attrs.check_allowed({"filename"}, tag, loc);
      parse_include(src, attrs.require("filename", tag, loc), loc, parent, depth);
      return;
    }
    if (tag == "alias") {
      attrs.check_allowed({"id", "as"}, tag, loc);
      auto it = ids_.find(attrs.require("id", tag, loc));
      if (it == ids_.end()) throw SceneError(loc, "<alias> of unknown id " + squote(*attrs.get("id")));
      register_id(attrs.require("as", tag, loc), it->second, loc);
      return;
    }
    if (tag == "null") return;  // Mitsuba 0.x placeholder object: nothing to build
    if (tag == "ref") {
      if (at_scene_level) throw SceneError(loc, "<ref> must be inside an object, not directly in <scene>");
      attrs.check_allowed({"id", "name"}, tag, loc);
      const std::string& id = attrs.require("id", tag, loc);
      auto it = ids_.find(id);
      if (it == ids_.end())
        throw SceneError(loc, "reference to unknown id " + squote(id) + " (objects must be defined before use)");
      const std::string* name = attrs.get("name");
      parent.children.push_back(it->second);
      parent.child_names.push_back(
          name ? xml::normalize_name(*name, src.version_major, parent.tag, parent.type) : "");
      return;
    }
    if (tag == "spectrum" && attrs.get("type")) {
      parse_object(src, el, attrs, parent, depth);  // Mitsuba 3 spectrum plugin (an object)
      return;
    }
    if (is_property_tag(tag)) {
      parse_property(src, el, tag, attrs, loc, parent);
      return;
    }
    if (is_object_tag(tag)) {
      parse_object(src, el, attrs, parent, depth);
      return;
    }
    if (tag == "animation") {
      parse_property(src, el, tag, attrs, loc, parent);
      return;
    }
    if (tag == "atransform") throw SceneError(loc, "<atransform> is not supported (use <animation>)");
    throw SceneError(loc, "unknown element <" + tag + ">");
  }

  void parse_property(Source& src, const pugi::xml_node& el, const std::string& tag, const Attrs& attrs,
                      const FileLoc& loc, SceneNode& parent) {
    Property prop;
    prop.written_name = attrs.require("name", tag, loc);
    if (prop.written_name.empty()) throw SceneError(loc, "<" + tag + "> needs a non-empty name");
    prop.name = xml::normalize_name(prop.written_name, src.version_major, parent.tag, parent.type);
    prop.loc = loc;
    for (const Property& p : parent.props)
      if (p.name == prop.name)
        throw SceneError(loc, "parameter " + squote(prop.written_name) + " of " + parent.describe() +
                                  " given twice (first at line " + std::to_string(p.loc.line) + ")");
    if (tag == "transform") {
      attrs.check_allowed({"name"}, tag, loc);
      Matrix4 m = Matrix4::identity();
      for (pugi::xml_node child : el.children()) {
        if (child.type() != pugi::node_element) continue;
        // Each element applies after those before it: T = T_new * T, as in Mitsuba.
        m = xml::parse_transform_element(child.name(), attrs_of(src, child), src.loc(child)) * m;
      }
      auto xf = Transform::from_matrix(m);
      if (!xf) throw SceneError(loc, "transform " + squote(prop.written_name) + " is singular or not finite");
      prop.type = PropType::Transform;
      prop.xf = *xf;
    } else if (tag == "animation") {
      attrs.check_allowed({"name"}, tag, loc);
      parse_animation(src, el, prop);
    } else if (!xml::parse_value_property(tag, attrs, loc, base_dir_, root_dir_, prop)) {
      throw SceneError(loc, "unknown element <" + tag + ">");
    } else if (const std::string* file = attrs.get("filename"); file && tag == "spectrum") {
      // Resolved as xml::read_spectrum_file just did: against the scene's directory.
      fs::path p(*file);
      if (p.is_relative() && !base_dir_.empty()) p = fs::path(base_dir_) / p;
      spectrum_files_.push_back(p.string());
    }
    parent.props.push_back(std::move(prop));
  }

  /// Mitsuba 0.6: <animation name=..> holds <transform time=".."> keyframes, strictly increasing.
  void parse_animation(Source& src, const pugi::xml_node& el, Property& prop) {
    for (pugi::xml_node key : el.children()) {
      if (key.type() != pugi::node_element) continue;
      const FileLoc kloc = src.loc(key);
      if (std::string_view(key.name()) != "transform")
        throw SceneError(kloc, "<animation> holds <transform time=..> keyframes, not <" + std::string(key.name()) + ">");
      Attrs kattrs = attrs_of(src, key);
      kattrs.check_allowed({"time"}, "transform", kloc);
      const double time = xml::parse_double(kattrs.require("time", "transform", kloc), kloc, "keyframe time");
      Matrix4 m = Matrix4::identity();
      for (pugi::xml_node child : key.children()) {
        if (child.type() != pugi::node_element) continue;
        m = xml::parse_transform_element(child.name(), attrs_of(src, child), src.loc(child)) * m;
      }
      auto xf = Transform::from_matrix(m);
      if (!xf) throw SceneError(kloc, "keyframe of " + squote(prop.written_name) + " is singular or not finite");
      if (m.m[3][0] != 0 || m.m[3][1] != 0 || m.m[3][2] != 0 || m.m[3][3] != 1)
        throw SceneError(kloc, "keyframe of " + squote(prop.written_name) + " is projective; keyframes must be affine");
      if (!prop.keyframes.empty() && !(float(time) > prop.keyframes.back().time))
        throw SceneError(kloc, "keyframe times of " + squote(prop.written_name) + " must increase strictly (" +
                                   std::to_string(time) + " after " + std::to_string(prop.keyframes.back().time) + ")");
      prop.keyframes.push_back({float(time), *xf});
    }
    if (prop.keyframes.empty())
      throw SceneError(prop.loc, "<animation> " + squote(prop.written_name) + " has no <transform time=..> keyframes");
    prop.type = PropType::Animation;
    prop.xf = prop.keyframes.front().xf;
  }

  void parse_object(Source& src, const pugi::xml_node& el, const Attrs& attrs, SceneNode& parent, int depth) {
    const std::string tag = el.name();
    const FileLoc loc = src.loc(el);
    auto node = std::make_shared<SceneNode>();
    node->loc = loc;
    if (tag == "shapegroup") {  // <shapegroup id=..> is read as <shape type="shapegroup" id=..>
      attrs.check_allowed({"id", "name"}, tag, loc);
      node->tag = "shape";
      node->type = "shapegroup";
    } else {
      attrs.check_allowed({"type", "id", "name"}, tag, loc);
      node->tag = tag;
      node->type = attrs.require("type", tag, loc);
      if (node->type.empty()) throw SceneError(loc, "<" + tag + "> needs a non-empty type");
    }
    if (const std::string* id = attrs.get("id")) node->id = *id;
    if (const std::string* name = attrs.get("name"))
      node->name = xml::normalize_name(*name, src.version_major, parent.tag, parent.type);
    parse_children(src, el, *node, depth + 1);
    if (src.version_major < 2) fold_uv_transform(*node);
    // Registered only now, so an object cannot refer to itself.
    if (!node->id.empty()) register_id(node->id, node, loc);
    parent.children.push_back(node);
    parent.child_names.push_back(node->name);
  }

  /// Mitsuba 0.x textures take uoffset/voffset/uscale/vscale; Mitsuba 3 one `to_uv` transform.
  /// Folded with 0.6's meaning, uv' = uv * scale + offset (Mitsuba 3's own upgrade applies the
  /// offset before the scale, which differs when both are given).
  static void fold_uv_transform(SceneNode& node) {
    static const char* const kNames[4] = {"uoffset", "voffset", "uscale", "vscale"};
    double v[4] = {0, 0, 1, 1};
    std::string written;
    FileLoc loc;
    bool any = false;
    // Scanned directly: SceneNode::find is for plugins and logs what they ask for.
    auto prop_named = [&node](const char* name) -> const Property* {
      for (const Property& p : node.props)
        if (p.name == name) return &p;
      return nullptr;
    };
    for (int i = 0; i < 4; ++i) {
      const Property* p = prop_named(kNames[i]);
      if (!p) continue;
      if (p->type != PropType::Float && p->type != PropType::Integer) return;  // the getter reports it
      v[i] = p->type == PropType::Float ? p->f : double(p->i);
      written += (written.empty() ? "" : "/") + p->written_name;
      if (!any || p->loc.line < loc.line) loc = p->loc;
      any = true;
    }
    if (!any || prop_named("to_uv")) return;
    Transform to_uv = Transform::translate(Vec3(float(v[0]), float(v[1]), 0.f)) *
                      Transform::scale(Vec3(float(v[2]), float(v[3]), 1.f));
    if (!Transform::from_matrix(to_uv.matrix()))
      throw SceneError(loc, "uscale/vscale of " + node.describe() + " must be non-zero");
    std::erase_if(node.props, [](const Property& p) {
      return p.name == "uoffset" || p.name == "voffset" || p.name == "uscale" || p.name == "vscale";
    });
    Property prop;
    prop.name = "to_uv";
    prop.written_name = written;
    prop.type = PropType::Transform;
    prop.loc = loc;
    prop.xf = to_uv;
    node.props.push_back(std::move(prop));
  }

  void register_id(const std::string& id, const std::shared_ptr<SceneNode>& node, const FileLoc& loc) {
    if (id.empty()) throw SceneError(loc, "empty id");
    auto [it, inserted] = ids_.emplace(id, node);
    if (!inserted)
      throw SceneError(loc, "duplicate id " + squote(id) + " (first used by " + it->second->describe() +
                                " at " + it->second->loc.str() + ")");
  }

  void parse_include(Source& src, const std::string& filename, const FileLoc& loc, SceneNode& parent,
                     int depth) {
    if (filename.empty()) throw SceneError(loc, "<include> needs a file name");
    fs::path name(filename);
    // Relative to the including file first; then, as Mitsuba's resolver, to the scene's directory.
    std::vector<std::pair<fs::path, fs::path>> candidates;  // (path to open, path for messages)
    if (name.is_absolute()) {
      candidates.emplace_back(name, name);
    } else {
      candidates.emplace_back(fs::path(src.dir) / name, (fs::path(src.dir) / name).lexically_normal());
      candidates.emplace_back(fs::path(base_dir_) / name, (fs::path(base_dir_) / name).lexically_normal());
    }
    // Confined, as LoadContext::resolve_path: candidates outside are not looked up.
    std::error_code ec;
    const std::pair<fs::path, fs::path>* found = nullptr;
    bool skipped_outside = false;
    for (const auto& c : candidates) {
      if (found) break;
      if (!detail::lexically_inside(root_dir_, c.first))
        skipped_outside = true;
      else if (fs::is_regular_file(c.first, ec))
        found = &c;
    }
    if (!found && skipped_outside) detail::throw_outside_root(loc, filename);
    if (!found) throw SceneError(loc, "cannot find included file " + squote(filename));
    if (!detail::canonically_inside(root_dir_, found->first)) detail::throw_outside_root(loc, filename);
    std::string canonical = fs::weakly_canonical(found->first, ec).string();
    if (std::find(include_stack_.begin(), include_stack_.end(), canonical) != include_stack_.end())
      throw SceneError(loc, "<include> cycle: " + squote(filename) + " is already being read");
    if (include_stack_.size() > size_t(kMaxIncludeDepth)) throw SceneError(loc, "<include>s nested too deeply");

    Source inc;
    inc.path = found->second.string();
    inc.dir = found->second.parent_path().string();
    std::ifstream in(found->first, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    if (!in && !in.eof()) throw SceneError(loc, "cannot read included file " + squote(filename));
    inc.text = ss.str();
    included_files_.push_back(found->first.string());
    pugi::xml_node root = load_document(inc, src.version_major);
    include_stack_.push_back(canonical);
    parse_children(inc, root, parent, depth + 1);
    include_stack_.pop_back();
  }
};

}  // namespace

SceneDesc parse_scene_string(const std::string& xml_text, const std::string& virtual_path,
                             const ParseOptions& options) {
  Parser parser(options);
  return parser.run(xml_text, virtual_path);
}

SceneDesc parse_scene_file(const std::string& path, const ParseOptions& options) {
  if (!detail::inside_root(options.root_dir, path)) detail::throw_outside_root(FileLoc{path, 0}, path);
  std::ifstream in(path, std::ios::binary);
  if (!in || fs::is_directory(path)) throw SceneError(FileLoc{path, 0}, "cannot open scene file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_scene_string(ss.str(), path, options);
}

}  // namespace tessera
