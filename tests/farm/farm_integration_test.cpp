// The farm end to end: a real coordinator and real workers (child processes) on loopback. Every
// finished image is compared bit for bit with an in-process render of the same settings, which is
// what `tessera render` produces.
#include "farm_harness.h"
#include "tessera/denoise/denoiser.h"

#include <cmath>
#include <iterator>

namespace tessera::test {
namespace {

// 100 wide with tiles of 24 (not a multiple); 37 spp (not a power of two): passes 1,2,4,8,16,6.
JobSettings small_job() {
  JobSettings s;
  s.name = "cornell-small";
  s.spp = 37;
  s.width = 100;
  s.height = 75;
  s.tile_size = 24;
  s.seed = 11;
  return s;
}

// Long enough (about 4 s on one thread) to kill things in the middle of it.
JobSettings long_job() {
  JobSettings s;
  s.name = "cornell-long";
  s.spp = 150;
  s.width = 120;
  s.height = 96;
  s.tile_size = 16;
  s.seed = 3;
  return s;
}

double progress(const nlohmann::json& j) { return j.value("progress", 0.0); }

// The coordinator and two local workers, registered.
bool start_with_two_workers(Farm& farm) {
  farm.start_server();
  farm.add_worker();
  farm.add_worker();
  return farm.wait_workers(2);
}

TEST(FarmIntegration, TwoWorkersStitchTheImageBitForBit) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  ASSERT_TRUE(start_with_two_workers(farm));
  const JobSettings settings = small_job();
  client::HttpReply reply;
  uint64_t id = farm.submit(cornell(), settings, &reply);
  ASSERT_GT(id, 0u) << reply.describe();
  nlohmann::json st = farm.wait_job(id);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump(2);
  EXPECT_EQ(st["passes"], 6);
  EXPECT_EQ(st["tiles"], 5 * 4);
  EXPECT_EQ(st["units_done"], st["units_total"]);
  EXPECT_EQ(st["workers"].size(), 2u) << "both workers should have rendered part of it: " << st["workers"].dump();
  Image farm_image = farm.image(id);
  Image local = local_render(cornell(), settings);
  ASSERT_EQ(farm_image.width(), 100);
  EXPECT_EQ(differing_pixels(farm_image, local), 0);
  std::printf("shares: %s\n", st["workers"].dump().c_str());
}

// Two workers on the long job; worker 0 is killed (kill -9: its leases in flight are lost) once the
// job is `at` done. Checks the finished image; returns the seconds until the coordinator saw the
// worker `lost`.
double kill_a_worker_at(double at) {
  Farm farm({"--heartbeat-interval", "0.5"});
  EXPECT_TRUE(start_with_two_workers(farm));
  const JobSettings settings = long_job();
  uint64_t id = farm.submit(cornell(), settings);
  EXPECT_GT(id, 0u);
  nlohmann::json before = farm.wait_until(id, [at](const nlohmann::json& j) { return progress(j) >= at; });
  EXPECT_EQ(before.value("state", ""), "running") << "the job ended before the worker could be killed";
  const auto killed = std::chrono::steady_clock::now();
  farm.worker(0).kill_now();
  std::string state;
  while (state != "lost" && std::chrono::steady_clock::now() - killed < std::chrono::seconds(10)) {
    const nlohmann::json workers = farm.client().get("/api/v1/workers").json();
    for (const auto& w : workers["workers"])
      if (w["name"] == "w0") state = w["state"];
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double noticed = std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  EXPECT_EQ(state, "lost");
  nlohmann::json st = farm.wait_job(id);
  EXPECT_EQ(st.value("state", ""), "done") << st.dump(2);
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - killed).count();
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), settings)), 0);
  EXPECT_EQ(st.value("mismatched_results", -1), 0);
  std::printf("killed a worker at %.0f%%: seen lost after %.2f s, job done %.2f s after the kill; %d leases for %d units\n",
              100 * progress(before), noticed, total, st.value("leases_issued", 0), st.value("units_total", 0));
  return state == "lost" ? noticed : -1;
}

TEST(FarmIntegration, KilledWorkerLeaseIsReissuedAndTheImageIsUnchanged) {
  TESSERA_REQUIRE_FILE(cornell());
  EXPECT_GE(kill_a_worker_at(0.2), 0);
}

// Near the end: the dead worker is noticed within 3 heartbeat intervals (not a long lease timeout),
// and its last units go to the worker left (speculative copies may take them even sooner).
TEST(FarmIntegration, KilledWorkerNearTheEndIsReplacedWithinTheHeartbeatBound) {
  TESSERA_REQUIRE_FILE(cornell());
  const double noticed = kill_a_worker_at(0.9);
  EXPECT_GE(noticed, 0);
  EXPECT_LT(noticed, 3 * 0.5 + 4.0) << "3 heartbeat intervals, plus the reaper's tick and slack for a busy machine";
}

TEST(FarmIntegration, KilledCoordinatorResumesWithoutRerenderingAcknowledgedPasses) {
  TESSERA_REQUIRE_FILE(cornell());
  // Without speculative copies every duplicate would be a unit rendered twice for the restart.
  Farm farm({"--no-speculation"});
  ASSERT_TRUE(start_with_two_workers(farm));
  // Few, slow units (up to 64 samples of 96x96 pixels each): the coordinator is killed while both
  // workers are inside one, so their leases are in flight across the restart.
  JobSettings settings = long_job();
  settings.spp = 320;
  settings.width = 192;
  settings.height = 96;
  settings.tile_size = 96;
  uint64_t id = farm.submit(cornell(), settings);
  ASSERT_GT(id, 0u);
  nlohmann::json mid = farm.wait_until(id, [](const nlohmann::json& j) { return progress(j) > 0.3; });
  ASSERT_EQ(mid.value("state", ""), "running");
  farm.kill_server();  // kill -9, mid-job; the workers keep their leases and retry
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  farm.start_server();  // same port, same data dir
  nlohmann::json resumed = farm.status(id);
  ASSERT_TRUE(resumed.is_object());
  EXPECT_GE(resumed.value("units_done", 0), mid.value("units_done", 0)) << "acknowledged passes were lost";
  nlohmann::json st = farm.wait_job(id);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump(2);
  EXPECT_EQ(st.value("reissued_acknowledged_passes", -1), 0);
  EXPECT_EQ(st.value("duplicate_results", -1), 0) << "leases in flight were re-issued instead of re-adopted";
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), settings)), 0);
  std::printf("coordinator killed at %d/%d units; after restart %d; leases issued %d, re-issued after ack %d\n",
              mid.value("units_done", 0), mid.value("units_total", 0), resumed.value("units_done", 0),
              st.value("leases_issued", 0), st.value("reissued_acknowledged_passes", -1));
}

// Speculation bounded by construction, end to end: a denoised job of 150 units on two workers, one
// killed at 30% and the coordinator killed and restarted at 60%, costs at most 1.2 leases a unit,
// never more than two of one unit, and nothing acknowledged is leased again (bench/speculation.sh
// measures the same).
TEST(FarmIntegration, KillsCostFewLeasesAndNothingAcknowledgedIsLeasedAgain) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm({"--heartbeat-interval", "0.5"});
  ASSERT_TRUE(start_with_two_workers(farm));
  JobSettings settings = long_job();
  settings.spp = 37;  // passes 1,2,4,8,16,6
  settings.width = settings.height = 200;
  settings.tile_size = 40;  // 25 tiles: 150 units
  settings.denoise = true;
  const uint64_t id = farm.submit(cornell(), settings);
  ASSERT_GT(id, 0u);
  farm.wait_until(id, [](const nlohmann::json& j) { return progress(j) >= 0.3; });
  farm.worker(0).kill_now();
  farm.wait_until(id, [](const nlohmann::json& j) { return progress(j) >= 0.6; });
  farm.kill_server();
  farm.start_server();
  const nlohmann::json st = farm.wait_job(id);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump(2);
  ASSERT_EQ(st.value("units_total", 0), 150);
  EXPECT_LE(st.value("leases_issued", 1000), 180) << "more than 1.2 leases a unit";
  EXPECT_LE(st.value("max_leases_per_unit", 100), 2);
  EXPECT_EQ(st.value("reissued_acknowledged_passes", -1), 0);
  std::printf("%d leases for %d units, at most %d of one, %d acknowledged re-issued\n", st.value("leases_issued", 0),
              st.value("units_total", 0), st.value("max_leases_per_unit", 0), st.value("reissued_acknowledged_passes", -1));
}

// Adaptive passes open at barriers whose counts the coordinator stores before leasing them: killed
// inside one, it resumes with the same counts, and the image is `tessera render --adaptive on`'s.
TEST(FarmIntegration, AdaptiveJobSurvivesAKilledCoordinatorBitForBit) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  ASSERT_TRUE(start_with_two_workers(farm));
  JobSettings settings = long_job();  // passes from sample 63 adapt (at a quarter of 150 or later)
  settings.adaptive = true;
  uint64_t id = farm.submit(cornell(), settings);
  ASSERT_GT(id, 0u);
  nlohmann::json mid = farm.wait_until(id, [](const nlohmann::json& j) { return progress(j) > 0.55; });
  ASSERT_EQ(mid.value("state", ""), "running");
  farm.kill_server();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  farm.start_server();
  nlohmann::json st = farm.wait_job(id);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump(2);
  EXPECT_EQ(st.value("samples_done", uint64_t(0)), uint64_t(120 * 96 * 150)) << "--spp is the total";
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), settings)), 0);
  std::printf("adaptive job: coordinator killed at %d/%d units\n", mid.value("units_done", 0),
              mid.value("units_total", 0));
}

// A guided job's trees are made by the coordinator from every tile's training records: killed in
// the middle of training, it rebuilds the tree in progress from the stored guide and records, and
// the image is `tessera render --guiding on`'s.
TEST(FarmIntegration, GuidedJobSurvivesAKilledCoordinatorDuringTrainingBitForBit) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  ASSERT_TRUE(start_with_two_workers(farm));
  JobSettings settings = long_job();  // passes ending within 75 samples (1, 3, 7, 15, 31, 63) train
  settings.guiding = true;
  uint64_t id = farm.submit(cornell(), settings);
  ASSERT_GT(id, 0u);
  nlohmann::json mid = farm.wait_until(id, [](const nlohmann::json& j) { return progress(j) > 0.15; });
  ASSERT_EQ(mid.value("state", ""), "running");
  EXPECT_LT(progress(mid), 0.42) << "killed after training (63 of 150 samples)";
  farm.kill_server();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  farm.start_server();
  nlohmann::json st = farm.wait_job(id);
  ASSERT_EQ(st.value("state", ""), "done") << st.dump(2);
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), settings)), 0);
  settings.guiding = false;
  EXPECT_GT(differing_pixels(farm.image(id), local_render(cornell(), settings)), 1000) << "the job was guided";
  std::printf("guided job: coordinator killed at %d/%d units\n", mid.value("units_done", 0), mid.value("units_total", 0));
}

TEST(FarmIntegration, HigherPriorityJobOvertakesAndCancelStopsAJob) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker();
  ASSERT_TRUE(farm.wait_workers(1));
  JobSettings low = long_job();
  low.priority = 0;
  uint64_t low_id = farm.submit(cornell(), low);
  ASSERT_GT(low_id, 0u);
  farm.wait_until(low_id, [](const nlohmann::json& j) { return j.value("units_done", 0) > 0; });
  JobSettings high = small_job();
  high.priority = 5;
  uint64_t high_id = farm.submit(cornell(), high);
  ASSERT_GT(high_id, 0u);
  nlohmann::json high_st = farm.wait_job(high_id);
  ASSERT_EQ(high_st.value("state", ""), "done");
  nlohmann::json low_st = farm.status(low_id);
  EXPECT_EQ(low_st.value("state", ""), "running") << "the high-priority job should finish first";

  client::HttpReply r = farm.client().del("/api/v1/jobs/" + std::to_string(low_id));
  EXPECT_EQ(r.status, 200) << r.describe();
  nlohmann::json cancelled = farm.wait_job(low_id, 10);
  EXPECT_EQ(cancelled.value("state", ""), "cancelled");
  // Cancelled work stops: the units done stay put, and a second cancel is refused.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_EQ(farm.status(low_id).value("units_done", -1), farm.status(low_id).value("units_done", -2));
  EXPECT_EQ(farm.client().del("/api/v1/jobs/" + std::to_string(low_id)).status, 409);
  // The partial image is still served, and the farm takes new work.
  EXPECT_EQ(farm.client().get("/api/v1/jobs/" + std::to_string(low_id) + "/image?format=png").status, 200);
  uint64_t again = farm.submit(cornell(), small_job());
  EXPECT_EQ(farm.wait_job(again).value("state", ""), "done");
  // Three jobs of one bundle: the worker downloaded it once.
  std::ifstream log(farm.log("worker0"));
  std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  size_t downloads = 0;
  for (size_t at = 0; (at = text.find("downloaded scene bundle", at)) != std::string::npos; ++at) ++downloads;
  EXPECT_EQ(downloads, 1u) << text;
}

TEST(FarmIntegration, WorkerJoiningMidJobGetsWork) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker();
  ASSERT_TRUE(farm.wait_workers(1));
  const JobSettings settings = long_job();
  uint64_t id = farm.submit(cornell(), settings);
  ASSERT_GT(id, 0u);
  farm.wait_until(id, [](const nlohmann::json& j) { return progress(j) > 0.1; });
  farm.add_worker();
  nlohmann::json st = farm.wait_job(id);
  ASSERT_EQ(st.value("state", ""), "done");
  ASSERT_EQ(st["workers"].size(), 2u) << st["workers"].dump();
  for (auto& w : st["workers"]) EXPECT_GT(w.value("samples", 0), 0);
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), settings)), 0);
}

TEST(FarmIntegration, WorkerStopsCleanlyOnSigterm) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker();
  ASSERT_TRUE(farm.wait_workers(1));
  uint64_t id = farm.submit(cornell(), long_job());
  farm.wait_until(id, [](const nlohmann::json& j) { return progress(j) > 0.1; });
  EXPECT_EQ(farm.worker(0).terminate(), 0);
  nlohmann::json workers = farm.client().get("/api/v1/workers").json();
  ASSERT_TRUE(workers.is_object());
  EXPECT_EQ(workers["workers"][0]["state"], "gone");
  // What it had not finished goes to the next worker at once (no lease timeout to wait for).
  farm.add_worker();
  EXPECT_EQ(farm.wait_job(id).value("state", ""), "done");
}

TEST(FarmIntegration, DrainedWorkerSignsOffAndExits) {
  Farm farm;
  farm.start_server();
  farm.add_worker();
  ASSERT_TRUE(farm.wait_workers(1));
  client::HttpReply r = farm.client().post_json("/api/v1/workers/1/drain", nlohmann::json::object());
  ASSERT_EQ(r.status, 200) << r.describe();
  EXPECT_EQ(farm.worker(0).wait_exit(20), 0);
  nlohmann::json workers = farm.client().get("/api/v1/workers").json();
  EXPECT_EQ(workers["workers"][0]["state"], "gone");
}

TEST(FarmIntegration, HeartbeatsKeepLongTilesLeased) {
  TESSERA_REQUIRE_FILE(cornell());
  // One 128x96 tile; its 64-sample pass takes seconds on one thread, longer than the 1.5 s lease
  // timeout (3 heartbeat intervals of 0.5 s): only the heartbeats keep it from being re-issued.
  Farm farm({"--heartbeat-interval", "0.5"});
  farm.start_server();
  farm.add_worker();
  ASSERT_TRUE(farm.wait_workers(1));
  JobSettings s;
  s.spp = 128;
  s.width = 128;
  s.height = 96;
  s.tile_size = 128;
  uint64_t id = farm.submit(cornell(), s);
  ASSERT_GT(id, 0u);
  nlohmann::json st = farm.wait_job(id);
  ASSERT_EQ(st.value("state", ""), "done");
  EXPECT_EQ(st.value("leases_issued", 0), st.value("units_total", -1)) << "a leased unit was re-issued";
  EXPECT_GT(st.value("elapsed_seconds", 0.0), 1.5) << "the job was too short to need a heartbeat";
  EXPECT_EQ(st.value("duplicate_results", -1), 0);
}

// The client as users run it: `tessera submit ... -o`, `tessera jobs`, `tessera cancel`.
TEST(FarmIntegration, SubmitCommandDownloadsTheSameImage) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker(2);
  ASSERT_TRUE(farm.wait_workers(1));
  const std::string out = (farm.dir().path / "sub" / "cornell.exr").string();
  const std::string png = (farm.dir().path / "cornell.png").string();
  const std::string log = farm.log("submit");
  const std::string cli = std::string(TESSERA_CLI_BIN) + " ";
  std::string cmd = cli + "submit " + cornell() + " --server " + farm.url() +
                    " --spp 37 --width 100 --height 75 --tile-size 24 --seed 11 --adaptive on --name from-cli -q -o " +
                    out + " -o " + png + " > " + log + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  JobSettings adaptive = small_job();
  adaptive.adaptive = true;
  EXPECT_EQ(differing_pixels(read_exr(out), local_render(cornell(), adaptive)), 0);
  EXPECT_TRUE(std::filesystem::file_size(png) > 100);

  const std::string jobs = farm.log("jobs");
  ASSERT_EQ(std::system((cli + "jobs --server " + farm.url() + " > " + jobs + " 2>&1").c_str()), 0);
  std::ifstream in(jobs);
  std::string listing((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(listing.find("from-cli"), std::string::npos) << listing;
  EXPECT_NE(listing.find("done"), std::string::npos) << listing;
  // Cancelling a finished job or an unknown one fails with the server's reason.
  EXPECT_NE(std::system((cli + "cancel 1 --server " + farm.url() + " > " + jobs + " 2>&1").c_str()), 0);
  EXPECT_NE(std::system((cli + "cancel 99 --server " + farm.url() + " > " + jobs + " 2>&1").c_str()), 0);
  // A scene that does not load fails before anything is sent.
  TempDir bad;
  std::string xml = bad.write("bad.xml", "<scene version=\"0.6.0\"><shape type=\"obj\"/></scene>");
  EXPECT_NE(std::system((cli + "submit " + xml + " --server " + farm.url() + " > " + jobs + " 2>&1").c_str()), 0);
  EXPECT_EQ(farm.client().get("/api/v1/jobs").json()["jobs"].size(), 1u);
}

// A denoised job as users run it, on two workers: `tessera submit --denoise -o OUT.exr` writes the
// denoised image and OUT.noisy.exr; the raw one (image and AOV layers) is `tessera render --aovs
// all`'s, and the denoised one is what `tessera denoise` makes of that raw image, bit for bit.
TEST(FarmIntegration, DenoisedJobIsTheLocalRenderAndItsDenoisedImage) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  ASSERT_TRUE(start_with_two_workers(farm));
  const std::string out = (farm.dir().path / "dn.exr").string(), noisy = (farm.dir().path / "dn.noisy.exr").string();
  const std::string local = (farm.dir().path / "local.exr").string(), again = (farm.dir().path / "again.exr").string();
  const std::string cli = std::string(TESSERA_CLI_BIN) + " ";
  const std::string flags = " --spp 37 --width 100 --height 75 --tile-size 24 --seed 11 -q";
  const std::string log = " > " + farm.log("denoise") + " 2>&1";
  ASSERT_EQ(std::system((cli + "submit " + cornell() + " --server " + farm.url() + flags + " --denoise -o " + out + log).c_str()), 0);
  ASSERT_EQ(std::system((cli + "render " + cornell() + flags + " --aovs all -o " + local + log).c_str()), 0);
  ASSERT_EQ(std::system((cli + "denoise " + noisy + " -o " + again + log).c_str()), 0);
  const DenoiseInput raw = read_denoise_input(noisy), expected = read_denoise_input(local);
  EXPECT_EQ(raw.color.values(), expected.color.values());
  EXPECT_EQ(raw.normal.values(), expected.normal.values());
  EXPECT_EQ(raw.half_b.values(), expected.half_b.values());
  EXPECT_EQ(read_exr(out).values(), read_exr(again).values());
  EXPECT_EQ(read_exr(out).values(), denoise(expected).values());
}

// The demo (scenes/demo, what scripts/demo.sh renders), smaller: through the farm with the
// denoiser it is `tessera render`'s image bit for bit, finite everywhere, raw and denoised, and it
// loads with nothing unsupported and no warning.
TEST(FarmIntegration, DemoSceneRendersThroughTheFarmAsLocally) {
  const std::string scene = std::string(TESSERA_SOURCE_DIR) + "/scenes/demo/scene.xml";
  Farm farm;
  ASSERT_TRUE(start_with_two_workers(farm));
  const std::string out = (farm.dir().path / "demo.exr").string(), noisy = (farm.dir().path / "demo.noisy.exr").string();
  const std::string local = (farm.dir().path / "local.exr").string();
  const std::string cli = std::string(TESSERA_CLI_BIN) + " ", flags = " --spp 6 --width 160 --height 100";
  const std::string submit_log = farm.log("demo-submit"), render_log = farm.log("demo-render");
  ASSERT_EQ(std::system((cli + "submit " + scene + " --server " + farm.url() + flags + " -q --denoise -o " + out +
                         " > " + submit_log + " 2>&1").c_str()),
            0);
  ASSERT_EQ(std::system((cli + "render " + scene + flags + " -o " + local + " > " + render_log + " 2>&1").c_str()), 0);
  const Image raw = read_exr(noisy), denoised = read_exr(out);
  EXPECT_EQ(differing_pixels(raw, read_exr(local)), 0);
  for (const Image* image : {&raw, &denoised})
    for (float v : image->values()) ASSERT_TRUE(std::isfinite(v));
  std::ifstream in(render_log);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (char& ch : text) ch = char(std::tolower(static_cast<unsigned char>(ch)));
  EXPECT_EQ(text.find("unsupported"), std::string::npos) << text;
  EXPECT_EQ(text.find("warning"), std::string::npos) << text;
  EXPECT_NE(text.find("render: 160x100, 6 spp"), std::string::npos) << text;
}

}  // namespace
}  // namespace tessera::test
