// The triangle soup of a list of OBJ files and folders, in the order ../shared/docs/rayfile.md
// defines, so triangle indices match ray-file hit records made by other tracers.
#pragma once

#include "tessera/core/vec.h"

#include <array>
#include <string>
#include <vector>

namespace tessera {

struct ObjSoup {
  std::vector<std::array<Vec3, 3>> triangles;
  std::vector<std::string> files;  // the OBJ files read, in soup order
};

/// Expands each entry: a file stays as given; a folder becomes every `*.obj` below it
/// (recursively), sorted by path. Throws SceneError for a path that does not exist.
std::vector<std::string> expand_obj_paths(const std::vector<std::string>& paths);

/// Loads the files of expand_obj_paths(paths) (in parallel; the order does not depend on it): each
/// file's shapes and faces in file order, polygons triangulated by tinyobjloader, no transforms.
/// Throws SceneError naming the file when one cannot be read or parsed.
ObjSoup load_obj_soup(const std::vector<std::string>& paths);

}  // namespace tessera
