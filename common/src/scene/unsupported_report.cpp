// After building: every node reachable from what was built is checked once. A plugin without a
// factory, a parameter no factory read, or a nested object nobody asked for becomes one
// UnsupportedItem (all of them reported together). Definitions nothing refers to (a top-level
// <bsdf>/<texture> without users, e.g. the bathroom's two bumpmaps whose ids sit on their inner
// BSDFs) are ignored, as Mitsuba ignores them.
//
// Image-neutral parameters: the list below names parameters that cannot change the rendered image
// (output format switches, options of features not modelled that are inert here, noise-only sampler
// settings). An unread one is not an error; it gets one informational note per kind:
//   film:    banner, file_format, pixel_format, component_format, attach_log, high_quality_edges,
//            dest_file, key and burn (only used by tonemap_method=reinhard, which is reported itself)
//   sensor:  focus_distance (a pinhole has no focus), shutter_open, shutter_close, shutter_open_time
//   sampler: scramble, seed, dimension, jitter (noise pattern only)
//   texture 'bitmap': filter_type ewa/trilinear/bilinear (MIP-mapping/filtering quality), max_anisotropy,
//            cache
//   emitter: sampling_weight (changes only how often a light is sampled, not the expectation)
//   any plugin: use_path_guiding (a private switch of some 0.6 forks)
//   bsdf 'dielectric'/'thindielectric'/'conductor'/'plastic': alpha, alpha_u, alpha_v, distribution
//            (the smooth plugins never read them, in Mitsuba 0.6 either)
// Note: ldrfilm `gamma`/`exposure` are NOT on the list: they are read.
#include "tessera/scene/load_context.h"

#include "scene/builder_internal.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>

namespace tessera::detail {

namespace {

struct Neutral {
  std::string_view tag;    // "" = any
  std::string_view type;   // "" = any
  std::string_view param;
  std::string_view values;  // comma-separated string values it is neutral for (lower case); "" = any
};

const Neutral kNeutral[] = {
    {"film", "", "banner", ""},
    {"film", "", "file_format", ""},
    {"film", "", "pixel_format", ""},
    {"film", "", "component_format", ""},
    {"film", "", "attach_log", ""},
    {"film", "", "high_quality_edges", ""},
    {"film", "", "dest_file", ""},
    {"film", "", "key", ""},
    {"film", "", "burn", ""},
    {"sensor", "", "focus_distance", ""},
    {"sensor", "", "shutter_open", ""},
    {"sensor", "", "shutter_close", ""},
    {"sensor", "", "shutter_open_time", ""},
    {"sampler", "", "scramble", ""},
    {"sampler", "", "seed", ""},
    {"sampler", "", "dimension", ""},
    {"sampler", "", "jitter", ""},
    {"texture", "bitmap", "filter_type", "ewa,trilinear,bilinear"},
    {"texture", "bitmap", "max_anisotropy", ""},
    {"texture", "bitmap", "cache", ""},
    {"emitter", "", "sampling_weight", ""},
    {"", "", "use_path_guiding", ""},
    {"bsdf", "dielectric", "alpha", ""},
    {"bsdf", "dielectric", "alpha_u", ""},
    {"bsdf", "dielectric", "alpha_v", ""},
    {"bsdf", "dielectric", "distribution", ""},
    {"bsdf", "thindielectric", "alpha", ""},
    {"bsdf", "thindielectric", "distribution", ""},
    {"bsdf", "conductor", "alpha", ""},
    {"bsdf", "conductor", "alpha_u", ""},
    {"bsdf", "conductor", "alpha_v", ""},
    {"bsdf", "conductor", "distribution", ""},
    {"bsdf", "plastic", "alpha", ""},
    {"bsdf", "plastic", "distribution", ""},
};

bool is_neutral(const SceneNode& node, const Property& p) {
  for (const Neutral& n : kNeutral) {
    if ((!n.tag.empty() && n.tag != node.tag) || (!n.type.empty() && n.type != node.type) || n.param != p.name)
      continue;
    if (n.values.empty()) return true;
    if (p.type != PropType::String || p.s.empty()) return false;
    std::string v;
    for (char c : p.s) v += char(std::tolower(static_cast<unsigned char>(c)));
    std::string_view rest = n.values;
    while (!rest.empty()) {
      size_t comma = rest.find(',');
      if (rest.substr(0, comma) == v) return true;
      rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    }
    return false;
  }
  return false;
}

bool plugin_supported(const SceneNode& node, const SceneNode* parent) {
  const std::string& t = node.type;
  if (node.tag == "bsdf") return find_bsdf_factory(t) != nullptr;
  if (node.tag == "texture") return find_texture_factory(t) != nullptr;
  if (node.tag == "shape") return t == "instance" || t == "shapegroup" || find_shape_factory(t) != nullptr;
  if (node.tag == "emitter") return t == "area" ? (parent && parent->tag == "shape") : find_light_factory(t) != nullptr;
  if (node.tag == "medium") return find_medium_factory(t) != nullptr;
  if (node.tag == "phase") return find_phase_factory(t) != nullptr;
  // Builders decide these themselves and report unsupported types directly.
  return node.tag == "sensor" || node.tag == "film" || node.tag == "sampler" || node.tag == "rfilter" ||
         node.tag == "integrator" || node.tag == "scene";
}

class Walker {
 public:
  explicit Walker(BuildState& st) : st_(st) {}

  /// Items in file/line order (the walk itself follows references, not the document).
  void emit_items() {
    std::stable_sort(items_.begin(), items_.end(), [](const UnsupportedItem& a, const UnsupportedItem& b) {
      return a.loc.file != b.loc.file ? a.loc.file < b.loc.file : a.loc.line < b.loc.line;
    });
    for (const auto& it : items_) st_.ctx.unsupported(it.loc, it.what, it.fallback);
  }

  void check(const SceneNode& node, const SceneNode* parent, const std::string& bound_as) {
    if (!visited_.insert(&node).second || st_.reported.count(&node)) return;
    if (!plugin_supported(node, parent)) {
      items_.push_back({node.loc, node.describe(), fallback_for(node)});
      return;
    }
    if (!node.used) {
      std::string where = parent ? " in " + parent->describe() : std::string();
      std::string as = bound_as.empty() ? std::string() : " (as '" + bound_as + "')";
      items_.push_back({node.loc, node.describe() + as + where + " is not used by the renderer", "ignored"});
      return;
    }
    if (!st_.params_exempt.count(&node)) {
      for (const Property& p : node.props) {
        if (p.used) continue;
        if (is_neutral(node, p)) {
          auto [it, fresh] = neutral_.try_emplace(node.tag + " '" + node.type + "'|" + p.written_name, p.loc, 0);
          ++it->second.second;
          if (fresh) order_.push_back(it->first);
          continue;
        }
        items_.push_back({p.loc, "parameter '" + p.written_name + "' of " + node.describe(), "ignored"});
      }
    }
    for (size_t i = 0; i < node.children.size(); ++i)
      check(*node.children[i], &node, i < node.child_names.size() ? node.child_names[i] : "");
  }

  void emit_notes() {
    for (const std::string& key : order_) {
      const auto& [loc, count] = neutral_[key];
      size_t bar = key.find('|');
      std::string text = "parameter '" + key.substr(bar + 1) + "' of " + key.substr(0, bar) +
                         " does not change the image; ignored";
      if (count > 1) text += " (" + std::to_string(count) + " places)";
      st_.ctx.note(loc, text);
    }
  }

 private:
  BuildState& st_;
  std::set<const SceneNode*> visited_;
  std::map<std::string, std::pair<FileLoc, int>> neutral_;
  std::vector<std::string> order_;
  std::vector<UnsupportedItem> items_;
};

}  // namespace

std::string fallback_for(const SceneNode& node) {
  const std::string& tag = node.tag;
  if (tag == "bsdf") return "diffuse, reflectance 0.5";
  if (tag == "texture") {
    Rgb c = texture_fallback_value(node);
    char buf[96];
    if (c.r == c.g && c.g == c.b)
      std::snprintf(buf, sizeof buf, "constant %g", double(c.r));
    else
      std::snprintf(buf, sizeof buf, "constant (%g, %g, %g)", double(c.r), double(c.g), double(c.b));
    return buf;
  }
  if (tag == "emitter") return "dropped";
  if (tag == "medium") return "ignored (vacuum)";
  if (tag == "phase") return "isotropic";
  if (tag == "shape") return "skipped";
  if (tag == "sensor") return "pinhole perspective camera with its to_world and fov";
  if (tag == "integrator") return "path";
  if (tag == "film") return "hdrfilm with its width and height";
  if (tag == "rfilter") return "gaussian (stddev 0.5)";
  if (tag == "sampler") return "independent";
  return "ignored";
}

Rgb texture_fallback_value(const SceneNode& node) {
  // Mean of Mitsuba's two-colour textures where their colours are plain values.
  if (node.type == "checkerboard" || node.type == "gridtexture") {
    auto color = [&](const char* name, Rgb def) {
      const Property* p = node.find(name);
      if (!p) return def;
      if (p->type == PropType::Color) return p->color;
      if (p->type == PropType::Float) return Rgb(float(p->f));
      return Rgb(0.5f);
    };
    return (color("color0", Rgb(0.4f)) + color("color1", Rgb(0.2f))) * 0.5f;
  }
  return Rgb(0.5f);
}

void report_unsupported(BuildState& st) {
  Walker w(st);
  const SceneNode& root = *st.desc.root;
  for (const Property& p : root.props)
    if (!p.used) st.ctx.unsupported(p.loc, "parameter '" + p.written_name + "' of the scene", "ignored");
  for (const auto& c : root.children) {
    // Definitions are checked where something uses them.
    bool definition = c->tag == "bsdf" || c->tag == "texture" || c->tag == "medium" || c->tag == "phase" ||
                      c->tag == "volume" || c->tag == "spectrum" || (c->tag == "shape" && c->type == "shapegroup");
    if (!definition) w.check(*c, &root, "");
  }
  w.emit_items();
  w.emit_notes();
}

}  // namespace tessera::detail
