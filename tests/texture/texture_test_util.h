// Helpers for the texture tests: a scratch directory for test images, and building textures from
// XML snippets through the real parser and LoadContext.
#pragma once

#include "test_support.h"

#include "tessera/scene/load_context.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <memory>
#include <string>
#include <unistd.h>

namespace tessera::test {

struct TextureTempDir {
  std::filesystem::path path;
  TextureTempDir() {
    static int counter = 0;
    path = std::filesystem::temp_directory_path() /
           ("tessera_texture_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(path);
  }
  ~TextureTempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

/// A parsed scene with a LoadContext over it; `texture(id)` builds the reflectance texture of the
/// bsdf with that id, as a BSDF factory would.
struct TextureScene {
  SceneDesc desc;
  Scene scene;
  LoadContext ctx;
  TextureScene(const std::string& body, const std::string& version = "3.0.0",
               const std::string& path = "mem/scene.xml")
      : desc(parse_scene_string("<scene version=\"" + version + "\">\n" + body + "\n</scene>\n", path)),
        ctx(desc, LoadOptions{}, scene) {}

  std::shared_ptr<Texture> texture(const std::string& bsdf_id, const std::string& param = "reflectance") {
    for (const auto& c : desc.root->children)
      if (c->id == bsdf_id) return ctx.texture(*c, param, Rgb(-1.f));
    ADD_FAILURE() << "no object with id " << bsdf_id;
    return nullptr;
  }
};

inline SurfaceInteraction at_uv(float u, float v) {
  SurfaceInteraction si;
  si.uv = Vec2(u, v);
  return si;
}

}  // namespace tessera::test
