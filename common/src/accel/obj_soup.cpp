#include "tessera/accel/obj_soup.h"

#include "tessera/core/error.h"

#include <tbb/parallel_for.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <filesystem>

namespace tessera {
namespace fs = std::filesystem;

namespace {

std::vector<std::array<Vec3, 3>> load_obj_triangles(const std::string& path) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config))
    throw SceneError(FileLoc{path, 0}, "cannot read OBJ file: " + reader.Error());
  const auto& v = reader.GetAttrib().vertices;
  auto vertex = [&](const tinyobj::index_t& idx) -> Vec3 {
    const size_t i = size_t(idx.vertex_index);
    if (idx.vertex_index < 0 || 3 * i + 2 >= v.size())
      throw SceneError(FileLoc{path, 0}, "vertex index " + std::to_string(idx.vertex_index) + " out of range");
    return {float(v[3 * i]), float(v[3 * i + 1]), float(v[3 * i + 2])};
  };
  std::vector<std::array<Vec3, 3>> tris;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& mesh = shape.mesh;
    size_t first = 0;
    for (const unsigned char n : mesh.num_face_vertices) {
      // tinyobjloader already triangulated; any polygon it left alone is fanned from its first vertex.
      for (size_t k = 1; k + 1 < n; ++k)
        tris.push_back({vertex(mesh.indices[first]), vertex(mesh.indices[first + k]),
                        vertex(mesh.indices[first + k + 1])});
      first += n;
    }
  }
  return tris;
}

}  // namespace

std::vector<std::string> expand_obj_paths(const std::vector<std::string>& paths) {
  std::vector<std::string> files;
  for (const std::string& p : paths) {
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<std::string> found;
      for (const auto& entry : fs::recursive_directory_iterator(p)) {
        if (entry.is_regular_file() && entry.path().extension() == ".obj")
          found.push_back(entry.path().generic_string());
      }
      std::sort(found.begin(), found.end());
      files.insert(files.end(), found.begin(), found.end());
    } else if (fs::exists(p, ec)) {
      files.push_back(p);
    } else {
      throw SceneError(FileLoc{p, 0}, "no such file or folder");
    }
  }
  return files;
}

ObjSoup load_obj_soup(const std::vector<std::string>& paths) {
  ObjSoup soup;
  soup.files = expand_obj_paths(paths);
  std::vector<std::vector<std::array<Vec3, 3>>> per_file(soup.files.size());
  // Exceptions from a task propagate to this thread (the first one thrown wins).
  tbb::parallel_for(size_t(0), soup.files.size(),
                    [&](size_t i) { per_file[i] = load_obj_triangles(soup.files[i]); });
  size_t total = 0;
  for (const auto& f : per_file) total += f.size();
  soup.triangles.reserve(total);
  for (auto& f : per_file) {
    soup.triangles.insert(soup.triangles.end(), f.begin(), f.end());
    f = {};
  }
  return soup;
}

}  // namespace tessera
