// docs/plugins.md lists every plugin and every parameter Tessera reads, and nothing else:
// - the plugins of each factory table are exactly the documented ones;
// - the parameters a plugin asks for while loading (tessera/scene/parameter_log.h; every shared
//   scene, plus one small scene per table plugin) are exactly the documented ones.
// TESSERA_PRINT_PARAMETERS=1 prints what was asked, to update the page from.
#include "tessera/scene/load_context.h"
#include "tessera/scene/parameter_log.h"
#include "tessera/scene/scene_desc.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <regex>
#include <set>

namespace tessera {
namespace {

using Documented = std::map<ParameterLog::Key, std::set<std::string>>;

// Sections "## TAG", rows "| `type` | `param`, `param` ... |" (a type `*` applies to all types of
// the section and is merged into each).
Documented read_docs(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in) << path;
  Documented out;
  std::map<std::string, std::set<std::string>> common;
  std::string line, tag;
  const std::regex tick("`([^`]+)`");
  while (std::getline(in, line)) {
    if (line.rfind("## ", 0) == 0) {
      tag = line.substr(3);
      continue;
    }
    if (tag.empty() || line.rfind("| `", 0) != 0) continue;
    size_t bar2 = line.find('|', 1), bar3 = line.find('|', bar2 + 1);
    std::string first = line.substr(1, bar2 - 1), second = line.substr(bar2 + 1, bar3 - bar2 - 1);
    std::smatch m;
    std::set<std::string> params;
    for (auto it = std::sregex_iterator(second.begin(), second.end(), tick); it != std::sregex_iterator(); ++it)
      params.insert((*it)[1]);
    for (auto it = std::sregex_iterator(first.begin(), first.end(), tick); it != std::sregex_iterator(); ++it) {
      std::string type = (*it)[1];
      if (type == "*") common[tag].insert(params.begin(), params.end());
      else out[{tag, type}].insert(params.begin(), params.end());
    }
  }
  for (auto& [key, params] : out) params.insert(common[key.first].begin(), common[key.first].end());
  return out;
}

std::string docs_path() { return test::source_dir() + "/docs/plugins.md"; }

TEST(PluginDocs, ListsExactlyTheRegisteredPlugins) {
  Documented docs = read_docs(docs_path());
  for (const char* tag : {"bsdf", "texture", "shape", "emitter", "medium", "phase"}) {
    std::set<std::string> registered, documented;
    for (const auto& t : registered_plugins(tag)) registered.insert(t);
    for (const auto& [key, params] : docs)
      if (key.first == tag) documented.insert(key.second);
    EXPECT_EQ(documented, registered) << "section ## " << tag << " of docs/plugins.md";
  }
}

// One small scene per table plugin, nested objects included where the plugin needs them.
std::string snippet(const std::string& tag, const std::string& type, const std::string& tex_file) {
  const std::string bitmap = "type=\"bitmap\"><string name=\"filename\" value=\"" + tex_file + "\"/></texture>";
  if (tag == "bsdf") {
    std::string nested;
    if (type == "blendbsdf") nested = "<bsdf type=\"diffuse\"/><bsdf type=\"diffuse\"/>";
    for (const char* wrapper : {"twosided", "mask", "bumpmap", "normalmap", "coating", "roughcoating"})
      if (type == wrapper) nested = "<bsdf type=\"diffuse\"/>";
    if (type == "bumpmap") nested += "<texture name=\"map\" " + bitmap;
    if (type == "normalmap") nested += "<texture name=\"normalmap\" " + bitmap;
    return "<shape type=\"sphere\"><bsdf type=\"" + type + "\">" + nested + "</bsdf></shape>";
  }
  if (tag == "texture") {
    std::string inner = type == "bitmap" ? "<string name=\"filename\" value=\"" + tex_file + "\"/>" : "";
    if (type == "scale") inner = "<texture name=\"texture\" type=\"checkerboard\"/>";
    return "<shape type=\"sphere\"><bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"" + type +
           "\">" + inner + "</texture></bsdf></shape>";
  }
  if (tag == "medium")
    return "<shape type=\"sphere\"><medium name=\"interior\" type=\"" + type + "\"/></shape>";
  if (tag == "phase")
    return "<shape type=\"sphere\"><medium name=\"interior\" type=\"homogeneous\"><phase type=\"" + type +
           "\"/></medium></shape>";
  if (tag == "emitter" && type == "area") return "<shape type=\"sphere\"><emitter type=\"area\"/></shape>";
  if (tag == "emitter" && type == "envmap")
    return "<emitter type=\"envmap\"><string name=\"filename\" value=\"" + tex_file + "\"/></emitter>";
  if (tag == "emitter") return "<emitter type=\"" + type + "\"/>";
  return "";  // shapes: the shared scenes use every file format; analytic ones below
}

TEST(PluginDocs, DocumentsExactlyTheParametersPluginsRead) {
  const std::string tex = test::shared_path("scenes/envmaps/bitterli_envmap.hdr");
  TESSERA_REQUIRE_FILE(tex);
  LoadOptions options;
  options.allow_unsupported = true;
  options.width = 8;
  options.height = 8;
  ParameterLog log;
  for (const char* s : {"cornell-box", "veach-mis", "veach-bidir", "living-room", "bathroom", "staircase2",
                        "kitchenette"}) {
    const std::string path = test::shared_path(std::string("scenes/") + s + "/scene.xml");
    TESSERA_REQUIRE_FILE(path);
    (void)load_scene(parse_scene_file(path), options);
  }
  std::string body;
  for (const char* tag : {"bsdf", "texture", "emitter", "medium", "phase"})
    for (const auto& type : registered_plugins(tag)) body += snippet(tag, type, tex) + "\n";
  for (const char* shape : {"sphere", "rectangle", "cube", "disk"})
    body += std::string("<shape type=\"") + shape + "\"/>\n";
  body += "<shape type=\"ply\"><string name=\"filename\" value=\"" + test::source_dir() +
          "/tests/scene/data/triangle.ply\"/></shape>\n";
  for (const char* integrator : {"path", "volpath", "direct", "bdpt", "ptracer"}) {
    std::string xml = std::string("<scene version=\"0.6.0\"><integrator type=\"") + integrator + "\"/>" +
                      "<sensor type=\"perspective\"><film type=\"hdrfilm\"/><sampler type=\"independent\"/>"
                      "</sensor>" + body + "</scene>";
    (void)load_scene(parse_scene_string(xml, "mem/catalog.xml"), options);
  }
  // The sensors the shared scenes do not use.
  for (const char* sensor : {"<sensor type=\"thinlens\"><float name=\"aperture_radius\" value=\"0.1\"/>"
                             "<float name=\"fov\" value=\"40\"/></sensor>",
                             "<sensor type=\"orthographic\"/>"}) {
    std::string xml = std::string("<scene version=\"0.6.0\">") + sensor + "<shape type=\"sphere\"/></scene>";
    (void)load_scene(parse_scene_string(xml, "mem/sensors.xml"), options);
  }

  Documented docs = read_docs(docs_path());
  bool print = std::getenv("TESSERA_PRINT_PARAMETERS") != nullptr;
  for (const auto& [key, asked] : log.asked()) {
    if (key.first == "scene" || key.second.empty()) continue;
    if (print) {
      std::printf("| `%s` `%s` |", key.first.c_str(), key.second.c_str());
      for (const auto& p : asked) std::printf(" `%s`", p.c_str());
      std::printf("\n");
    }
    auto it = docs.find(key);
    bool supported_type = key.first != "bsdf" && key.first != "texture" && key.first != "shape" &&
                                  key.first != "emitter" && key.first != "medium" && key.first != "phase"
                              ? true
                              : [&] {
                                  for (const auto& t : registered_plugins(key.first))
                                    if (t == key.second) return true;
                                  return false;
                                }();
    if (!supported_type) continue;  // an unsupported plugin asks for nothing; reported elsewhere
    if (it == docs.end()) {
      ADD_FAILURE() << key.first << " '" << key.second << "' is read but not in docs/plugins.md";
      continue;
    }
    for (const auto& p : asked)
      EXPECT_TRUE(it->second.count(p)) << key.first << " '" << key.second << "' reads '" << p
                                       << "', which docs/plugins.md does not list";
    for (const auto& p : it->second)
      EXPECT_TRUE(asked.count(p)) << key.first << " '" << key.second << "': docs/plugins.md lists '" << p
                                  << "', which it never reads";
  }
}

}  // namespace
}  // namespace tessera
