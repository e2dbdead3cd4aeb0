// Shared resources while loading: paths, textures, BSDFs and meshes built once per node or file,
// and the messages/unsupported items collected for the report.
#include "tessera/scene/load_context.h"

#include "tessera/core/check.h"

#include "scene/builder_internal.h"
#include "scene/path_confinement.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace tessera {

namespace fs = std::filesystem;

LoadContext::LoadContext(const SceneDesc& desc, const LoadOptions& options, Scene& scene)
    : desc_(desc), options_(options), scene_(scene) {
  for (LookaheadPass pass : lookahead_passes()) pass(*this);
}

std::string LoadContext::resolve_path(const std::string& name, const FileLoc& loc) const {
  std::string path = locate_file(name, loc);
  if (resolved_set_.insert(path).second) resolved_files_.push_back(path);
  return path;
}

std::string LoadContext::locate_file(const std::string& name, const FileLoc& loc) const {
  if (name.empty()) throw SceneError(loc, "empty file name");
  // The scene's directory first (Mitsuba's resolver), then the directory of the XML file that
  // names the file (an included file's neighbours). Windows separators in old scenes are accepted.
  std::vector<fs::path> candidates;
  for (std::string n : {name, [&] {
                          std::string s = name;
                          std::replace(s.begin(), s.end(), '\\', '/');
                          return s;
                        }()}) {
    fs::path p(n);
    if (p.is_absolute()) {
      candidates.push_back(p);
      continue;
    }
    candidates.push_back(fs::path(desc_.base_dir) / p);
    if (!loc.file.empty()) candidates.push_back(fs::path(loc.file).parent_path() / p);
  }
  // Confined (a bundle): a candidate outside the root is not even looked up, so that the error
  // does not tell whether a file outside exists; one inside that turns out to be a symlink out is
  // refused rather than skipped.
  const std::string& root = root_dir();
  bool skipped_outside = false;
  std::error_code ec;
  for (const fs::path& c : candidates) {
    if (!detail::lexically_inside(root, c)) {
      skipped_outside = true;
      continue;
    }
    if (!fs::is_regular_file(c, ec)) continue;
    if (!detail::canonically_inside(root, c)) detail::throw_outside_root(loc, name);
    if (!std::ifstream(c, std::ios::binary)) throw SceneError(loc, "cannot read '" + c.string() + "'");
    return c.string();
  }
  if (skipped_outside) detail::throw_outside_root(loc, name);
  throw SceneError(loc, "file not found: '" + name + "' (looked in '" +
                            (desc_.base_dir.empty() ? std::string(".") : desc_.base_dir) + "')");
}

std::shared_ptr<Texture> LoadContext::texture(const SceneNode& node, const std::string& name, Rgb def) {
  std::shared_ptr<SceneNode> child = node.named_child(name);
  if (child) {
    if (child->tag != "texture")
      throw SceneError(child->loc, child->describe() + " given as '" + name + "' of " + node.describe() +
                                       " is not a texture");
    child->used = true;
    auto it = textures_.find(child.get());
    if (it != textures_.end()) return it->second;
    std::shared_ptr<Texture> tex;
    if (TextureFactory f = find_texture_factory(child->type)) {
      tex = f(*child, *this);
      if (!tex) throw SceneError(child->loc, child->describe() + ": the texture plugin returned nothing");
    } else {
      // Reported by the final walk; this is the documented fallback.
      tex = std::make_shared<ConstantTexture>(detail::texture_fallback_value(*child));
    }
    textures_[child.get()] = tex;
    scene_.textures.push_back(tex);
    return tex;
  }
  return std::make_shared<ConstantTexture>(node.get_color(name, def));
}

std::shared_ptr<const MeshData> LoadContext::cached_mesh(const std::string& key,
                                                         const std::function<MeshData()>& load) {
  auto it = meshes_.find(key);
  if (it != meshes_.end()) return it->second;
  auto mesh = std::make_shared<const MeshData>(load());
  meshes_.emplace(key, mesh);
  return mesh;
}

const Bsdf* LoadContext::bsdf(const std::shared_ptr<SceneNode>& node) {
  const SceneNode* key = node.get();
  auto it = bsdfs_.find(key);
  if (it != bsdfs_.end()) return it->second;
  BsdfFactory factory = nullptr;
  if (node) {
    if (node->tag != "bsdf")
      throw SceneError(node->loc, node->describe() + " is used where a bsdf is expected");
    node->used = true;
    factory = find_bsdf_factory(node->type);
    if (!factory) {
      // Unsupported (reported by the final walk): the default BSDF stands in.
      const Bsdf* fallback = bsdf(nullptr);
      bsdfs_[key] = fallback;
      return fallback;
    }
  }
  std::shared_ptr<Bsdf> made;
  if (node) {
    made = factory(*node, *this);
  } else {
    // Mitsuba's default: diffuse with reflectance 0.5.
    BsdfFactory diffuse = find_bsdf_factory("diffuse");
    if (!diffuse) throw SceneError("no 'diffuse' BSDF is registered for shapes without a BSDF");
    SceneNode def;
    def.tag = "bsdf";
    def.type = "diffuse";
    made = diffuse(def, *this);
  }
  if (!made) throw SceneError(node ? node->loc : FileLoc{}, "the bsdf plugin returned nothing");
  scene_.bsdfs.push_back(made);
  bsdfs_[key] = made.get();
  return made.get();
}

const Medium* LoadContext::medium(const std::shared_ptr<SceneNode>& node) {
  TESSERA_CHECK(node != nullptr);
  auto it = media_.find(node.get());
  if (it != media_.end()) return it->second;
  MediumFactory factory = find_medium_factory(node->type);
  const Medium* out = nullptr;
  if (factory) {
    node->used = true;
    std::shared_ptr<Medium> made = factory(*node, *this);
    if (!made) throw SceneError(node->loc, "the medium plugin returned nothing");
    scene_.media.push_back(made);
    out = made.get();
  }
  media_[node.get()] = out;
  return out;
}

std::shared_ptr<const PhaseFunction> LoadContext::phase(const SceneNode& medium_node) {
  auto phases = medium_node.children_with_tag("phase");
  if (phases.size() > 1) throw SceneError(phases[1]->loc, medium_node.describe() + " has more than one phase function");
  if (!phases.empty()) {
    const SceneNode& p = *phases[0];
    if (PhaseFactory factory = find_phase_factory(p.type)) {
      p.used = true;
      std::shared_ptr<PhaseFunction> made = factory(p, *this);
      if (!made) throw SceneError(p.loc, "the phase plugin returned nothing");
      return made;
    }
    // Unsupported type: reported by the final walk; isotropic stands in.
  }
  return make_isotropic_phase();
}

const Bsdf* LoadContext::null_bsdf() {
  if (!null_bsdf_) {
    BsdfFactory factory = find_bsdf_factory("null");
    TESSERA_CHECK(factory != nullptr);
    SceneNode def;
    def.tag = "bsdf";
    def.type = "null";
    std::shared_ptr<Bsdf> made = factory(def, *this);
    scene_.bsdfs.push_back(made);
    null_bsdf_ = made.get();
  }
  return null_bsdf_;
}

void LoadContext::note(const FileLoc& loc, const std::string& text) {
  messages_.push_back({LoadMessage::Level::Note, loc, text});
}

void LoadContext::warn(const FileLoc& loc, const std::string& text) {
  messages_.push_back({LoadMessage::Level::Warning, loc, text});
}

void LoadContext::unsupported(const FileLoc& loc, const std::string& what, const std::string& fallback) {
  unsupported_.push_back({loc, what, fallback});
  if (options_.allow_unsupported) warn(loc, "unsupported: " + what + " (fallback: " + fallback + ")");
}

}  // namespace tessera
