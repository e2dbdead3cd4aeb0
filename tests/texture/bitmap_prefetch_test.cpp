// Decoding a scene's bitmaps ahead of the build, in the background: every file is decoded once,
// the files a scene is said to need are unchanged, and the loaded texels are the same bytes
// whatever the number of threads.
#include "tessera/texture/bitmap.h"
#include "tessera/texture/bitmap_prefetch.h"

#include "texture/test_image_files.h"
#include "texture/texture_test_util.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <vector>

namespace tessera {
namespace {

using test::TextureScene;
using test::TextureTempDir;

// Five files of every stored kind, larger than a texel or two so that decoding takes a while.
std::vector<std::string> write_files(const TextureTempDir& dir) {
  const int w = 64, h = 48;
  std::vector<std::string> paths;
  Image im(w, h, 4);
  for (size_t i = 0; i < im.values().size(); ++i) im.data()[i] = float((i * 31) % 256) / 255.f;
  paths.push_back(dir.file("a.png"));
  write_png(paths.back(), im, LdrSettings{1.f, 0.f});
  paths.push_back(dir.file("b.exr"));
  write_exr(paths.back(), im);
  std::vector<uint16_t> codes(im.values().size());
  for (size_t i = 0; i < codes.size(); ++i) codes[i] = uint16_t((i * 7919) % 65536);
  paths.push_back(dir.file("c.png"));
  test::write_png16(paths.back(), w, h, 4, codes);
  std::vector<float> v(im.values().begin(), im.values().end());
  for (float& x : v) x = x * 20.f + 0.01f;
  paths.push_back(dir.file("d.exr"));
  test::write_half_exr(paths.back(), w, h, 4, v);
  paths.push_back(dir.file("e.jpg"));  // a missing file: reported by the factory, not the prefetch
  return paths;
}

std::string bsdf(const std::string& id, const std::string& path, const std::string& extra = "") {
  return "<bsdf type=\"diffuse\" id=\"" + id + "\"><texture type=\"bitmap\" name=\"reflectance\">"
         "<string name=\"filename\" value=\"" + path + "\"/>" + extra + "</texture></bsdf>";
}

std::string scene_body(const std::vector<std::string>& p) {
  std::string body = bsdf("a", p[0]) + bsdf("b", p[1], "<float name=\"gamma\" value=\"2.2\"/>") + bsdf("c", p[2]) +
                     bsdf("d", p[3], "<string name=\"channel\" value=\"a\"/>") +
                     bsdf("a2", p[0], "<string name=\"wrap_mode\" value=\"clamp\"/>");
  for (const char* id : {"a", "b", "c", "d", "a2"})
    body += std::string("<shape type=\"rectangle\"><ref id=\"") + id + "\"/></shape>";
  return body;
}

TEST(BitmapPrefetch, TheLoadStartsDecodingEveryFileOfTheScene) {
  TextureTempDir dir;
  const auto paths = write_files(dir);
  // Two bsdfs no shape uses: one names a missing file, one a decoding nothing else needs.
  TextureScene s(scene_body(paths) + bsdf("missing", paths[4]) +
                 bsdf("unused", paths[1], "<boolean name=\"raw\" value=\"true\"/>"));
  const BitmapPrefetch* ahead = bitmap_prefetch(s.ctx);
  ASSERT_NE(ahead, nullptr);
  // a.png (twice, one decoding), b.exr with gamma, c.png, d.exr's alpha: four, all decoded;
  // nothing for the unused bsdfs.
  EXPECT_EQ(ahead->wait_all(), 4u);
  EXPECT_EQ(ahead->get(bitmap_cache_key(paths[1], BitmapDecodeSettings{0.f, true, -1})), nullptr);
  // Looking ahead does not count a file as used before the build uses it.
  EXPECT_TRUE(s.ctx.resolved_files().empty());
  // The build takes the decoded texels rather than decoding again.
  const auto& a = dynamic_cast<const BitmapTexture&>(*s.texture("a"));
  const std::string key = bitmap_cache_key(paths[0], BitmapDecodeSettings{});
  EXPECT_EQ(a.texels().get(), &ahead->get(key)->texels);
  ASSERT_EQ(s.ctx.resolved_files().size(), 1u);
  EXPECT_EQ(s.ctx.resolved_files()[0], paths[0]);
  // The missing file is still reported where the scene names it.
  const std::string msg = test::scene_error_of([&] { s.texture("missing"); });
  EXPECT_NE(msg.find("e.jpg"), std::string::npos) << msg;
}

TEST(BitmapPrefetch, TheBuildDecodesWhatNoTaskHasStartedYet) {
  // A one-thread arena whose only thread is busy with the build, so no task can start: the
  // factory must decode the file it needs itself (waiting for a task would never return).
  TextureTempDir dir;
  const auto paths = write_files(dir);
  tbb::task_arena arena(1);
  arena.execute([&] {
    TextureScene s(scene_body(paths));
    const auto& a = dynamic_cast<const BitmapTexture&>(*s.texture("c"));
    const Image got = a.texels()->to_image();
    const Image want = decode_bitmap_file(paths[2], BitmapDecodeSettings{}).texels.to_image();
    EXPECT_TRUE(got.values() == want.values());
  });
}

LoadResult load_in_arena(int threads, const SceneDesc& desc) {
  tbb::task_arena arena(threads);
  LoadResult r;
  arena.execute([&] { r = load_scene(desc, LoadOptions{}); });
  return r;
}

TEST(BitmapPrefetch, ParallelLoadGivesTheSerialTexels) {
  // Allow 4 threads even on a 2-core machine, so that the 4-thread load is really parallel.
  tbb::global_control allow(tbb::global_control::max_allowed_parallelism, 4);
  TextureTempDir dir;
  const auto paths = write_files(dir);
  const SceneDesc desc = parse_scene_string("<scene version=\"3.0.0\">" + scene_body(paths) + "</scene>",
                                            dir.file("scene.xml"));
  const LoadResult one = load_in_arena(1, desc);
  for (int threads : {2, 4}) {
    const LoadResult many = load_in_arena(threads, desc);
    EXPECT_EQ(one.files, many.files) << threads << " threads";
    ASSERT_EQ(one.scene->textures.size(), many.scene->textures.size());
    ASSERT_EQ(one.scene->textures.size(), 5u);
    for (size_t i = 0; i < one.scene->textures.size(); ++i) {
      const auto& a = *dynamic_cast<const BitmapTexture&>(*one.scene->textures[i]).texels();
      const auto& b = *dynamic_cast<const BitmapTexture&>(*many.scene->textures[i]).texels();
      EXPECT_EQ(a.format(), b.format()) << i;
      const Image ia = a.to_image(), ib = b.to_image();
      ASSERT_EQ(ia.values().size(), ib.values().size()) << i;
      EXPECT_EQ(std::memcmp(ia.data(), ib.data(), ia.values().size() * sizeof(float)), 0)
          << "texture " << i << ", " << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace tessera
