// Helpers shared by tests: locating ../shared, and skip-or-fail when an input is missing.
#pragma once

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "tessera/scene/error.h"

namespace tessera::test {

inline std::string shared_dir() { return TESSERA_SHARED_DIR; }
inline std::string source_dir() { return TESSERA_SOURCE_DIR; }
inline std::string shared_path(const std::string& rel) { return shared_dir() + "/" + rel; }
inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

/// A fresh directory under the system temp dir, removed at scope exit.
struct TempDir {
  std::filesystem::path path;
  TempDir() {
    static int counter = 0;
    path = std::filesystem::temp_directory_path() /
           ("tessera_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    // (A test that crashed left its folder; a later process may reuse its pid.)
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// Writes `text` to `name` (sub-folders created) and returns the full path.
  std::string write(const std::string& name, const std::string& text) const {
    std::filesystem::path p = path / name;
    std::filesystem::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
};

/// The message of the SceneError `f` throws; fails the test when it throws none.
template <typename F>
std::string scene_error_of(F&& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a SceneError";
  return "";
}

}  // namespace tessera::test

/// Skips the test when `path` is missing, except under CI=true, where it fails.
#define TESSERA_REQUIRE_FILE(path)                                                         \
  do {                                                                                     \
    if (!std::filesystem::exists(path)) {                                                  \
      if (::tessera::test::in_ci()) FAIL() << "required file missing: " << (path);         \
      GTEST_SKIP() << "file missing: " << (path);                                          \
    }                                                                                      \
  } while (0)
