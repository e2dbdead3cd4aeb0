// Loading a scene around an <integrator> for the loader tests of Tessera's own integrators: the
// integrator on line 2 and its parameters one per line after it (parameter i, from 0, on line
// 3 + i), then `rest` (a sensor by default) and a sphere.
#pragma once

#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"

#include <string>

namespace tessera::test {

inline const char* kPerspective = R"(<sensor type="perspective"><float name="fov" value="40"/>
  <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/></film></sensor>
)";

/// load(integrator, rest, version, options): the scene of file name `file` (messages name it).
struct IntegratorLoader {
  std::string file;
  LoadResult operator()(const std::string& integrator, const std::string& rest = kPerspective,
                        const std::string& version = "0.6.0", const LoadOptions& opt = {}) const {
    const std::string xml = "<scene version=\"" + version + "\">\n" + integrator + "\n" + rest +
                            "<shape type=\"sphere\"/>\n</scene>\n";
    return load_scene(parse_scene_string(xml, file), opt);
  }
};

inline size_t count_messages(const LoadResult& r, LoadMessage::Level level, const std::string& text) {
  size_t n = 0;
  for (const auto& m : r.messages) n += m.level == level && m.text.find(text) != std::string::npos;
  return n;
}

}  // namespace tessera::test
