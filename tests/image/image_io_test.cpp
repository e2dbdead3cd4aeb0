// The read_image / write_image dispatcher and the shared environment maps.
#include "image/image_test_util.h"
#include "tessera/image/image.h"
#include "tessera/image/image_compare.h"
#include "tessera/scene/error.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace tessera {
namespace {

using test::scratch_dir;

std::string error_of(const std::string& path) {
  try {
    read_image(path);
  } catch (const SceneError& e) {
    EXPECT_EQ(e.loc().file, path);
    return e.what();
  }
  ADD_FAILURE() << "no error reading " << path;
  return {};
}

TEST(ImageIo, EveryEnvmapInSharedLoads) {
  std::filesystem::path dir = test::shared_path("scenes/envmaps");
  TESSERA_REQUIRE_FILE(dir.string());
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::string ext = entry.path().extension().string();
    if (ext != ".exr" && ext != ".hdr") continue;
    SCOPED_TRACE(entry.path().filename().string());
    Image img = read_image(entry.path().string());
    EXPECT_GE(img.width(), 2);
    EXPECT_GE(img.height(), 3);
    EXPECT_TRUE(img.channels() == 3 || img.channels() == 4);
    EXPECT_EQ(count_non_finite(img), 0u);
    auto m = channel_means(img);
    EXPECT_GT(m[0] + m[1] + m[2], 0.0);
    ++loaded;
  }
  EXPECT_EQ(loaded, 7);
}

TEST(ImageIo, LivingRoomEnvmapWithASpaceInItsNameLoads) {
  std::string path = test::shared_path("scenes/living-room/textures/Sky 19.exr");
  TESSERA_REQUIRE_FILE(path);
  Image img = read_image(path);
  EXPECT_GT(img.num_pixels(), 0u);
}

TEST(ImageIo, DispatchByExtensionRoundTrips) {
  auto dir = scratch_dir();
  Image img = test::test_pattern(5, 4, 3, 3, /*allow_negative=*/false);
  for (const char* name : {"a.exr", "a.EXR", "a.pfm", "a.png", "a.hdr"}) {
    std::string path = (dir / name).string();
    write_image(path, img);
    Image back = read_image(path);
    EXPECT_EQ(back.width(), 5) << name;
    EXPECT_EQ(back.height(), 4) << name;
  }
}

TEST(ImageIo, MissingFileErrorNamesIt) {
  auto dir = scratch_dir();
  for (const char* name : {"none.exr", "none.png", "none.pfm", "none.hdr"}) {
    std::string path = (dir / name).string();
    std::string msg = error_of(path);
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
  }
}

TEST(ImageIo, GarbageFilesAreErrorsNamingThem) {
  auto dir = scratch_dir();
  for (const char* name : {"bad.exr", "bad.png", "bad.hdr", "bad.jpg", "bad.pfm", "empty.exr"}) {
    std::string path = (dir / name).string();
    test::write_bytes(path, std::string(name) == "empty.exr" ? "" : "this is not an image at all\n");
    std::string msg = error_of(path);
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
  }
}

TEST(ImageIo, TruncatedPngIsAnError) {
  auto dir = scratch_dir();
  std::string good = (dir / "good.png").string(), cut = (dir / "cut.png").string();
  write_png(good, test::test_pattern(64, 64, 3, 2, false));
  std::string bytes = test::read_bytes(good);
  test::write_bytes(cut, bytes.substr(0, bytes.size() / 2));
  std::string msg = error_of(cut);
  EXPECT_NE(msg.find(cut), std::string::npos) << msg;
}

TEST(ImageIo, UnsupportedExtensionsAreErrors) {
  auto dir = scratch_dir();
  std::string path = (dir / "picture.webp").string();
  test::write_bytes(path, "RIFF");
  std::string msg = error_of(path);
  EXPECT_NE(msg.find(".webp"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_THROW(write_image((dir / "out.tiff").string(), Image(1, 1, 3)), SceneError);
  EXPECT_THROW(write_image((dir / "noext").string(), Image(1, 1, 3)), SceneError);
}

TEST(ImageIo, DirectoryIsNotAnImage) {
  auto dir = scratch_dir();
  std::string path = (dir / "sub.exr").string();
  std::filesystem::create_directory(path);
  std::string msg = error_of(path);
  EXPECT_NE(msg.find("not a regular file"), std::string::npos) << msg;
}

TEST(Image, AccessorsAndConversions) {
  Image img(3, 2, 1);
  img.set_rgb(2, 1, Rgb(0.3f, 0.6f, 0.9f));
  EXPECT_FLOAT_EQ(img.at(2, 1, 0), 0.6f);
  EXPECT_EQ(img.rgb(2, 1), Rgb(img.at(2, 1, 0)));
  EXPECT_EQ(img.alpha(0, 0), 1.f);
  Image rgb = img.to_rgb();
  EXPECT_EQ(rgb.channels(), 3);
  EXPECT_EQ(rgb.rgb(2, 1), img.rgb(2, 1));
  rgb.flip_vertical();
  EXPECT_EQ(rgb.rgb(2, 0), img.rgb(2, 1));
  EXPECT_EQ(rgb.rgb(2, 1), Rgb(0.f));

  Image enc(1, 1, 4);
  enc.set_rgb(0, 0, Rgb(0.5f));
  enc.at(0, 0, 3) = 0.5f;
  enc.set_srgb_encoded(true);
  Image lin = enc.linearized();
  EXPECT_NEAR(lin.at(0, 0, 0), srgb_to_linear(0.5f), 1e-7f);
  EXPECT_EQ(lin.at(0, 0, 3), 0.5f);
}

}  // namespace
}  // namespace tessera
