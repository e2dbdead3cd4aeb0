// Helpers for the shape tests: a per-process scratch directory and exception matching.
#pragma once

#include "tessera/scene/error.h"
#include "tessera/shape/mesh_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace tessera::test {

/// A per-process scratch directory, removed when the test binary exits.
inline std::filesystem::path scratch_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() : path(std::filesystem::temp_directory_path() /
                 ("tessera_shape_test_" + std::to_string(::getpid()))) {
      std::filesystem::create_directories(path);
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

inline std::string write_scratch(const std::string& name, const std::string& bytes) {
  std::string path = (scratch_dir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  return path;
}

/// Runs `f`, expecting a SceneError whose message names `path`'s file and contains `needle`.
inline void expect_scene_error(const std::function<void()>& f, const std::string& path,
                               const std::string& needle = "") {
  try {
    f();
    ADD_FAILURE() << "expected SceneError for " << path;
  } catch (const SceneError& e) {
    std::string msg = e.what();
    std::string file = std::filesystem::path(path).filename().string();
    EXPECT_NE(msg.find(file), std::string::npos) << "message lacks file name: " << msg;
    if (!needle.empty()) {
      EXPECT_NE(msg.find(needle), std::string::npos) << "message: " << msg;
    }
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected SceneError, got std::exception: " << e.what();
  }
}

/// Sum of triangle areas of a mesh.
inline double mesh_area(const MeshData& m) {
  double a = 0;
  for (size_t t = 0; t < m.num_triangles(); ++t) {
    Vec3 p0 = m.positions[m.indices[3 * t]], p1 = m.positions[m.indices[3 * t + 1]],
         p2 = m.positions[m.indices[3 * t + 2]];
    a += 0.5 * double(length(cross(p1 - p0, p2 - p0)));
  }
  return a;
}

}  // namespace tessera::test
