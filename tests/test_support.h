// Helpers shared by tests: locating ../shared, and skip-or-fail when an input is missing.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace tessera::test {

inline std::string shared_dir() { return TESSERA_SHARED_DIR; }
inline std::string source_dir() { return TESSERA_SOURCE_DIR; }
inline std::string shared_path(const std::string& rel) { return shared_dir() + "/" + rel; }
inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
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
