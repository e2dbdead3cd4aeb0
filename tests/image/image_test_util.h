// Helpers for the image tests: a per-test scratch directory and a deterministic test pattern.
#pragma once

#include "tessera/core/hash.h"
#include "tessera/image/image.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace tessera::test {

/// Fresh directory under the system temp dir, named after the running test.
inline std::filesystem::path scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto dir = std::filesystem::temp_directory_path() /
             ("tessera_image_test_" + std::string(info->test_suite_name()) + "_" + info->name());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// Values spanning what renders contain: zeros, tiny, large, negative (for float formats).
inline Image test_pattern(int w, int h, int channels, uint64_t seed = 1, bool allow_negative = true) {
  Image img(w, h, channels);
  Pcg32 rng(seed);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) {
        float u = rng.next_float();
        float v = u < 0.1f ? 0.f : (u < 0.2f ? 1e-6f * u : (u < 0.3f ? 1e4f * u : u));
        if (allow_negative && rng.next_float() < 0.1f) v = -v;
        img.at(x, y, c) = v;
      }
  return img;
}

inline void write_bytes(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary);
  out << bytes;
}

inline std::string read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace tessera::test
