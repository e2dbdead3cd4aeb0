// The worker's scene cache: one load per scene and settings, shared between slots, least recently
// used evicted beyond the memory budget, failures not cached.
#include "tessera/farm/bundle.h"
#include "tessera/farm/sha256.h"
#include "tessera/scene/error.h"
#include "tessera/worker/scene_cache.h"
#include "test_support.h"

#include <fstream>

namespace tessera::test {
namespace {

// A bundle placed in the cache directory as if downloaded, so no server is needed.
Lease cached_lease(const TempDir& dir, const std::string& xml, int width) {
  TempDir src;
  src.write("scene.xml", xml);
  std::string bundle = pack_bundle(src.path.string(), {"scene.xml"});
  Lease l;
  l.settings.scene = sha256_hex(bundle);
  l.settings.width = width;
  l.settings.height = 8;
  l.scene_file = "scene.xml";
  l.files = {"scene.xml"};
  std::filesystem::create_directories(dir.path / "bundles");
  std::ofstream(dir.path / "bundles" / (l.settings.scene + ".bundle"), std::ios::binary) << bundle;
  return l;
}

constexpr const char* kXml = "<scene version=\"0.6.0\"><shape type=\"sphere\"/>"
                             "<emitter type=\"constant\"/></scene>";

TEST(SceneCache, LoadsOnceAndEvictsLeastRecentlyUsed) {
  TempDir dir;
  const client::FarmApi nowhere(client::FarmClient("http://127.0.0.1:9"));  // never contacted: bundles are in the cache
  Lease a = cached_lease(dir, kXml, 8), b = a, c = a;
  b.settings.width = 9;
  c.settings.width = 10;
  {
    farm::SceneCache cache(dir.path.string(), /*budget=*/1);  // room for one scene only
    auto first = cache.get(a, nowhere);
    auto again = cache.get(a, nowhere);
    EXPECT_EQ(first.get(), again.get()) << "the same settings share one loaded scene";
    EXPECT_EQ(first->scene->film.width, 8);
    first.reset();
    again.reset();
    EXPECT_EQ(cache.get(b, nowhere)->scene->film.width, 9);
    EXPECT_EQ(cache.loaded_scenes(), 1u) << "a was evicted for b";
    auto held = cache.get(c, nowhere);  // b is not in use: evicted
    EXPECT_EQ(cache.loaded_scenes(), 1u);
    auto also = cache.get(a, nowhere);  // c is in use (held): it stays, over budget
    EXPECT_EQ(cache.loaded_scenes(), 2u);
    EXPECT_EQ(cache.downloads(), 0u);
  }
  farm::SceneCache roomy(dir.path.string(), uint64_t(1) << 32);
  const auto sa = roomy.get(a, nowhere), sb = roomy.get(b, nowhere);
  EXPECT_EQ(roomy.loaded_scenes(), 2u);
  // What the worker reports in its heartbeats: each scene as Scene::memory counts it.
  const WorkerMemory m = roomy.memory();
  EXPECT_EQ(m.scenes, 2u);
  EXPECT_GT(sa->scene->memory().accel, 0u);
  EXPECT_EQ(sa->bytes, sa->scene->memory().total());
  EXPECT_EQ(m.scene_bytes, sa->bytes + sb->bytes);
}

TEST(SceneCache, FailuresAreReportedAndNotCached) {
  TempDir dir;
  const client::FarmApi nowhere(client::FarmClient("http://127.0.0.1:9"));
  Lease bad = cached_lease(dir, "<scene version=\"0.6.0\"><shape type=\"obj\"><string name=\"filename\" "
                                "value=\"missing.obj\"/></shape></scene>", 8);
  farm::SceneCache cache(dir.path.string(), uint64_t(1) << 30);
  EXPECT_THROW((void)cache.get(bad, nowhere), SceneError);
  EXPECT_EQ(cache.loaded_scenes(), 0u);
  Lease missing = bad;
  missing.settings.scene = std::string(64, 'e');  // not cached, and the server is unreachable
  try {
    (void)cache.get(missing, nowhere);
    ADD_FAILURE() << "expected a download failure";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot download"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tessera::test
