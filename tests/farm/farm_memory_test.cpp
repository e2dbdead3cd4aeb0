// The coordinator's memory does not grow with submissions: a large scene is planned in a
// short-lived child process, and a job's film is allocated only when its first result arrives.
// A looser bound than the benchmark's (bench/coordinator_memory.sh), with fewer cycles. Bundles
// are sent to workers from disk, a chunk at a time, and workers write them to disk as they come.
#include "archive_builder.h"
#include "farm_harness.h"
#include "tessera/farm/sha256.h"

#include <atomic>
#include <fstream>
#include <thread>

namespace tessera::test {
namespace {

using nlohmann::json;

double resident_mb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string key; in >> key;) {
    if (key == "VmRSS:") {
      double kb = 0;
      in >> kb;
      return kb / 1024;
    }
    in.ignore(1 << 20, '\n');
  }
  return -1;
}

TEST(FarmMemory, SubmissionsOfALargeSceneLeaveNoRenderStateBehind) {
  const std::string scene = shared_path("scenes/living-room/scene.xml");
  TESSERA_REQUIRE_FILE(scene);
  Farm farm;
  farm.start_server();
  // One upload; then jobs name the bundle by its hash, as a frame range or a re-render would.
  JobSettings settings;
  auto abs = std::filesystem::absolute(scene);
  LoadedJobScene loaded = load_job_scene(abs.parent_path().string(), abs.filename().string(), settings, false);
  BundlePlan plan = plan_bundle(abs.string(), scene_files(loaded.desc, loaded.loaded));
  client::HttpReply up = farm.api().upload_scene(pack_bundle(plan.root_dir, plan.files));
  ASSERT_EQ(up.status, 201) << up.body;
  const json body = {{"scene", up.json()["hash"]}, {"scene_file", plan.files.front()}, {"spp", 64},
                     {"width", 1280}, {"height", 720}};
  const double start = resident_mb(farm.server_pid());
  for (int i = 0; i < 8; ++i) {
    client::HttpReply r = farm.api().submit_job(body);
    ASSERT_EQ(r.status, 201) << r.body;
    ASSERT_TRUE(farm.api().cancel_job(r.json()["id"]).ok());
  }
  const double cycled = resident_mb(farm.server_pid());
  for (int i = 0; i < 8; ++i) ASSERT_EQ(farm.api().submit_job(body).status, 201);
  const double queued = resident_mb(farm.server_pid());
  std::printf("coordinator RSS: %.0f MB at start, %.0f MB after 8 submit+cancel, %.0f MB with 8 jobs queued\n", start,
              cycled, queued);
  // In-process loading kept ~150 MB per living-room submission; a 1280x720 film is 52 MB.
  EXPECT_LT(cycled, 250);
  EXPECT_LT(queued, 250);
}

// Four workers fetching a 48 MB bundle at once cost the coordinator a few megabytes, not four
// copies of it (what reading the file whole for each download took).
TEST(FarmMemory, BundlesAreSentFromDiskAChunkAtATime) {
  Farm farm;
  farm.start_server();
  const std::string bundle =
      ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("scene.xml", "<scene version=\"0.6.0\"/>").file("big.bin", noise(48u << 20, 9)).finish();
  const client::HttpReply up = farm.api().upload_scene(bundle);
  ASSERT_EQ(up.status, 201) << up.body;
  const std::string hash = up.json()["hash"];
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // (the upload's buffers given back)
  const double before = resident_mb(farm.server_pid());
  std::atomic<bool> done{false};
  double peak = before;
  std::thread sampler([&] {
    while (!done) {
      peak = std::max(peak, resident_mb(farm.server_pid()));
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  });
  TempDir dir;
  std::vector<std::thread> downloads;
  std::vector<int> status(4, 0);
  for (int i = 0; i < 4; ++i)
    downloads.emplace_back([&, i] {
      status[size_t(i)] = farm.api().download_scene(hash, (dir.path / std::to_string(i)).string()).status;
    });
  for (auto& t : downloads) t.join();
  done = true;
  sampler.join();
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(status[size_t(i)], 200);
    EXPECT_EQ(sha256_file_hex((dir.path / std::to_string(i)).string()), hash) << "download " << i;
  }
  std::printf("coordinator: %.1f MB before, %.1f MB at most while sending 4 x %.1f MB\n", before, peak,
              double(bundle.size()) / 1e6);
  EXPECT_LT(peak - before, 24.0) << "the coordinator held the bundle whole";
}

}  // namespace
}  // namespace tessera::test
