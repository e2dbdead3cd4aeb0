// The worker's scene cache: one load per scene and settings, shared between slots, least recently
// used evicted beyond the memory budget, failures not cached.
#include "tessera/farm/bundle.h"
#include "tessera/farm/sha256.h"
#include "tessera/sequence/guide_artifact.h"
#include "tessera/sequence/photon_program.h"
#include "tessera/scene/error.h"
#include "tessera/worker/scene_cache.h"
#include "test_support.h"

#include <httplib.h>

#include <atomic>
#include <fstream>
#include <map>
#include <thread>

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

// A coordinator that serves artifacts (GET /api/v1/guides/HASH) and counts the requests.
struct ArtifactServer {
  httplib::Server http;
  std::map<std::string, std::string> by_hash;
  std::atomic<int> requests{0};
  std::thread thread;
  int port = 0;
  ArtifactServer() {
    http.Get(R"(/api/v1/guides/([0-9a-f]{64}))", [this](const httplib::Request& req, httplib::Response& res) {
      ++requests;
      auto it = by_hash.find(req.matches[1].str());
      if (it == by_hash.end()) {
        res.status = 404;
        return;
      }
      res.set_content(it->second, "application/octet-stream");
    });
    port = http.bind_to_any_port("127.0.0.1");
    thread = std::thread([this] { http.listen_after_bind(); });  // (bound: connections wait in the backlog)
  }
  ~ArtifactServer() {
    http.stop();
    thread.join();
  }
  std::string url() const { return "http://127.0.0.1:" + std::to_string(port); }
};

// An artifact a lease renders with (a guide) is fetched once, checked against its hash, decoded,
// counted in the worker's memory as it costs (Artifact::memory_bytes), and evicted beyond the
// budget like a scene.
TEST(SceneCache, ArtifactsAreFetchedOnceCheckedAndCountedAgainstTheBudget) {
  TempDir dir;
  ArtifactServer server;
  Bounds3 box;
  box.extend(Vec3(0.f, 0.f, 0.f));
  box.extend(Vec3(1.f, 1.f, 1.f));
  SpatialTree grown(box);
  GuidingSettings settings;
  settings.spatial_threshold = 1;
  for (int i = 0; i < 64; ++i) grown.record(grown.leaf_of(Vec3(0.1f, 0.2f, 0.3f)), Vec3(0, 0, 1), 1.f, 0.5f);
  grown.end_iteration(4, settings);
  const std::string bytes = encode_guide(grown), hash = sha256_hex(bytes);
  server.by_hash[hash] = bytes;
  const std::string wrong = std::string(64, 'a');
  server.by_hash[wrong] = bytes;  // (bytes that are not what their name says)
  const client::FarmApi api{client::FarmClient(server.url())};
  Lease lease;
  lease.job_id = 3;
  lease.guide = Lease::Guide{hash, 1, false};
  const Scene path_scene;  // (a guide is a path tracer's)
  {
    farm::SceneCache cache(dir.path.string(), uint64_t(1) << 30);
    auto first = cache.guide(lease, api, path_scene);
    auto again = cache.guide(lease, api, path_scene);
    EXPECT_EQ(first.get(), again.get());
    EXPECT_EQ(server.requests.load(), 1) << "fetched once";
    ASSERT_TRUE(first->guide);
    EXPECT_TRUE(*first->guide == grown) << "decoded to the tree it encodes";
    EXPECT_EQ(first->bytes, grown.bytes());
    EXPECT_EQ(cache.memory().scene_bytes, grown.bytes()) << "what a heartbeat reports";
    Lease corrupt = lease;
    corrupt.guide->hash = wrong;
    try {
      (void)cache.guide(corrupt, api, path_scene);
      ADD_FAILURE() << "a guide whose bytes are not its hash's was taken";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("hash mismatch"), std::string::npos) << e.what();
    }
  }
  farm::SceneCache tight(dir.path.string(), /*budget=*/1);
  Lease scene = cached_lease(dir, kXml, 8);
  (void)tight.guide(lease, api, path_scene);
  EXPECT_EQ(tight.loaded_scenes(), 1u);
  (void)tight.get(scene, api);  // the guide is not in use: evicted for the scene
  EXPECT_EQ(tight.loaded_scenes(), 1u);
  EXPECT_EQ(tight.memory().scenes, 1u);
}

// An sppm job's artifact is its photon map: decoded with its grid, as the scene's integrator says.
TEST(SceneCache, AnSppmJobsArtifactIsItsPhotonMap) {
  TempDir dir;
  ArtifactServer server;
  std::vector<Photon> photons(100);
  for (size_t i = 0; i < photons.size(); ++i) {
    photons[i].p[0] = float(i) * 0.01f;
    photons[i].power[1] = 1.f;
    photons[i].length = 2;
  }
  const std::string bytes = PointRecordsArtifact(0.05f, {grid_records(photons)}).encode(), hash = sha256_hex(bytes);
  server.by_hash[hash] = bytes;
  const client::FarmApi api{client::FarmClient(server.url())};
  Lease lease;
  lease.job_id = 4;
  lease.guide = Lease::Guide{hash, 0, false};
  Scene sppm_scene;
  sppm_scene.integrator.type = IntegratorType::Sppm;
  farm::SceneCache cache(dir.path.string(), uint64_t(1) << 30);
  auto map = cache.guide(lease, api, sppm_scene);
  const auto* grid = dynamic_cast<const PhotonMapArtifact*>(map->points.get());
  ASSERT_NE(grid, nullptr);
  EXPECT_EQ(grid->grid().size(), photons.size());
  EXPECT_EQ(grid->grid().max_radius(), 0.05f);
  EXPECT_EQ(cache.memory().scene_bytes, grid->memory_bytes()) << "counted against the budget";
  EXPECT_FALSE(map->guide);
}

}  // namespace
}  // namespace tessera::test
