// Every shared scene loads, builds its BVH and renders (tiny, with --allow-unsupported), listing
// exactly what is unsupported; cornell-box has nothing unsupported at all.
#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "tessera/sequence/renderer.h"
#include "tessera/scene/load_context.h"
#include "tessera/scene/scene_desc.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <set>

namespace tessera {
namespace {

class SharedScene : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedScene, LoadsAndRendersWithAllowUnsupported) {
  const std::string path = test::shared_path(std::string("scenes/") + GetParam() + "/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  LoadOptions options;
  options.allow_unsupported = true;
  options.width = 64;
  options.height = 48;
  options.spp = 2;
  LoadResult loaded = load_scene(parse_scene_file(path), options);
  ASSERT_TRUE(loaded.scene);
  EXPECT_GT(loaded.scene->num_triangles() + loaded.scene->shapes.size(), 0u);
  for (const auto& item : loaded.unsupported)
    std::printf("%s: unsupported: %s: %s (fallback: %s)\n", GetParam(), item.loc.str().c_str(), item.what.c_str(),
                item.fallback.c_str());

  RenderSettings settings;
  settings.spp = 2;
  RenderStats stats;
  Film film = render(*loaded.scene, settings, {}, &stats);
  Image image = film.to_image();
  EXPECT_EQ(count_non_finite(image), 0u);
  EXPECT_EQ(image.width(), 64);
  EXPECT_EQ(image.height(), 48);
}

INSTANTIATE_TEST_SUITE_P(All, SharedScene,
                         ::testing::Values("cornell-box", "veach-mis", "veach-bidir", "living-room", "bathroom",
                                           "staircase2", "kitchenette"));

TEST_P(SharedScene, WithoutAllowUnsupportedLoadsOrListsEveryItemWithItsLine) {
  // Either the scene loads cleanly, or the load fails once with every unsupported item listed, each
  // with file and line (the message lists them all, one per line).
  const std::string path = test::shared_path(std::string("scenes/") + GetParam() + "/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  LoadOptions options;
  options.width = 16;
  options.height = 16;
  try {
    LoadResult loaded = load_scene(parse_scene_file(path), options);
    EXPECT_TRUE(loaded.unsupported.empty());
  } catch (const UnsupportedError& e) {
    ASSERT_FALSE(e.items().empty());
    const std::string what = e.what();
    for (const auto& item : e.items()) {
      EXPECT_NE(item.loc.file.find("scene.xml"), std::string::npos);
      EXPECT_GT(item.loc.line, 0);
      EXPECT_NE(what.find(item.loc.str() + ": " + item.what), std::string::npos) << what;
    }
  }
}

TEST(SharedScene, CornellBoxHasNothingUnsupported) {
  const std::string path = test::shared_path("scenes/cornell-box/scene.xml");
  TESSERA_REQUIRE_FILE(path);
  LoadOptions options;
  options.width = 16;
  options.height = 16;
  LoadResult loaded = load_scene(parse_scene_file(path), options);
  EXPECT_TRUE(loaded.unsupported.empty());
  for (const auto& m : loaded.messages) EXPECT_EQ(m.level, LoadMessage::Level::Note) << m.text;
}

}  // namespace
}  // namespace tessera
