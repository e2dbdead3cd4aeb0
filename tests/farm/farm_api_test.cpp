// The coordinator's HTTP API against bad input: every malformed request gets a clear 4xx with a
// JSON body, and the server stays healthy and keeps its accepted work.
#include "archive_builder.h"
#include "farm_harness.h"
#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/tile_result.h"

#include <atomic>
#include <map>
#include <sstream>

namespace tessera::test {
namespace {

using nlohmann::json;

// Asserts status and that the body is {"error": ..., "detail": ...}; returns the detail.
std::string expect_error(const client::HttpReply& r, int status) {
  EXPECT_EQ(r.status, status) << r.body;
  json j = r.json();
  EXPECT_TRUE(j.is_object() && j.contains("error") && j.contains("detail")) << r.body;
  return j.is_object() ? j.value("detail", "") : "";
}

std::string bundle_with(const std::string& name, const std::string& xml) {
  ArchiveBuilder b(ArchiveBuilder::Format::TarGz);
  b.file(name, xml);
  return b.finish();
}

class FarmApi : public ::testing::Test {
 protected:
  void SetUp() override { farm_.start_server(); }
  void TearDown() override {
    // Whatever was thrown at it, the coordinator is healthy.
    EXPECT_TRUE(farm_.client().get("/healthz", 5).ok());
  }
  client::HttpReply post_job(const json& settings, const std::string& bundle) {
    return farm_.api().submit_job(settings, bundle);
  }
  Farm farm_;
};

TEST_F(FarmApi, MalformedJsonUnknownFieldsAndAbsurdSizes) {
  auto c = farm_.client();
  expect_error(c.post_bytes("/api/v1/jobs", "{not json", "application/json"), 400);
  std::string detail = expect_error(c.post_json("/api/v1/jobs", json{{"scene", std::string(64, 'a')}, {"sp", 4}}), 400);
  EXPECT_NE(detail.find("unknown field 'sp'"), std::string::npos) << detail;
  detail = expect_error(c.post_json("/api/v1/jobs", json{{"scene", std::string(64, 'a')}, {"spp", "many"}}), 400);
  EXPECT_NE(detail.find("'spp'"), std::string::npos) << detail;
  detail = expect_error(c.post_json("/api/v1/jobs", json{{"scene", std::string(64, 'a')}, {"width", 1000000}}), 422);
  EXPECT_NE(detail.find("width"), std::string::npos) << detail;
  // A number out of its field's range is a 422 naming the field and the range, however far out.
  const std::string scene = "{\"scene\": \"" + std::string(64, 'a') + "\", ";
  for (const char* spp : {"18446744073709551616", "-5", "2.5", "1e40"}) {
    detail = expect_error(c.post_bytes("/api/v1/jobs", scene + "\"spp\": " + spp + "}", "application/json"), 422);
    EXPECT_NE(detail.find("spp"), std::string::npos) << detail;
    EXPECT_NE(detail.find(".."), std::string::npos) << "no range in: " << detail;
  }
  detail = expect_error(c.post_bytes("/api/v1/jobs", scene + "\"seed\": -1}", "application/json"), 422);
  EXPECT_NE(detail.find("'seed' must be an integer in 0..4294967295"), std::string::npos) << detail;
  expect_error(c.post_json("/api/v1/jobs", json{{"scene", std::string(64, 'a')}}), 404);  // no such bundle
  expect_error(c.post_json("/api/v1/jobs", json::array({1, 2})), 400);
  expect_error(c.get("/api/v1/jobs/999"), 404);
  expect_error(c.get("/api/v1/jobs/99999999999999999999999"), 400);
  expect_error(c.get("/api/v1/nothing-here"), 404);
  expect_error(c.get("/api/v1/scenes/" + std::string(64, 'b')), 404);
  expect_error(c.post_json("/api/v1/workers", json{{"name", "x"}}), 400);
  expect_error(c.post_json("/api/v1/workers/77/lease", json::object()), 404);
}

TEST_F(FarmApi, HostileAndBrokenBundlesAreRefused) {
  auto c = farm_.client();
  const std::string xml = "<scene version=\"0.6.0\"><shape type=\"sphere\"/></scene>";
  struct Case {
    const char* what;
    std::string bundle;
  };
  std::string good = bundle_with("scene.xml", xml);
  std::vector<Case> cases = {
      {"escaping path", ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("../evil.xml", xml).finish()},
      {"absolute path", ArchiveBuilder(ArchiveBuilder::Format::Zip).file("/etc/evil.xml", xml).finish()},
      {"symlink", ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("scene.xml", xml).symlink("mesh.obj", "/etc/passwd").finish()},
      {"truncated", good.substr(0, good.size() / 2)},
      {"random bytes", noise(4000, 9)},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.what);
    expect_error(c.post_bytes("/api/v1/scenes", k.bundle, "application/gzip"), 400);
    expect_error(post_job(json::object(), k.bundle), 400);
  }
  // A good bundle is stored once, by hash.
  client::HttpReply a = c.post_bytes("/api/v1/scenes", good, "application/gzip");
  client::HttpReply b = c.post_bytes("/api/v1/scenes", good, "application/gzip");
  ASSERT_EQ(a.status, 201) << a.body;
  EXPECT_EQ(a.json()["hash"], b.json()["hash"]);
  EXPECT_EQ(c.get("/api/v1/scenes/" + a.json()["hash"].get<std::string>()).body, good);
}

TEST_F(FarmApi, SceneThatFailsToLoadGetsTheLoadersMessage) {
  // A parse error names the file and line inside the bundle.
  std::string detail = expect_error(
      post_job(json::object(), bundle_with("broken.xml", "<scene version=\"0.6.0\">\n<shape type=\"sphere\">\n</scene>")),
      422);
  EXPECT_NE(detail.find("broken.xml:"), std::string::npos) << detail;
  EXPECT_EQ(detail.find(farm_.dir().path.string()), std::string::npos) << "leaks the data dir: " << detail;
  // A missing mesh file.
  detail = expect_error(
      post_job(json::object(), bundle_with("mesh.xml", "<scene version=\"0.6.0\"><shape type=\"obj\">"
                                                           "<string name=\"filename\" value=\"gone.obj\"/></shape></scene>")),
      422);
  EXPECT_NE(detail.find("gone.obj"), std::string::npos) << detail;
  EXPECT_EQ(detail.find(farm_.dir().path.string()), std::string::npos) << "leaks the data dir: " << detail;
  // Two XML files and no choice.
  ArchiveBuilder two(ArchiveBuilder::Format::TarGz);
  two.file("a.xml", "<scene version=\"0.6.0\"/>").file("b.xml", "<scene version=\"0.6.0\"/>");
  expect_error(post_job(json::object(), two.finish()), 422);
  EXPECT_EQ(farm_.client().get("/api/v1/jobs").json()["jobs"].size(), 0u);
}

TEST_F(FarmApi, WorkerProtocolRefusesBadBuildsAndBadResults) {
  TESSERA_REQUIRE_FILE(cornell());
  auto c = farm_.client();
  const BuildFingerprint& fp = build_fingerprint();
  std::string detail = expect_error(
      c.post_json("/api/v1/workers", json{{"version", fp.version}, {"isa", "other"}, {"probe", std::string(64, '0')}}), 409);
  EXPECT_NE(detail.find("different bits"), std::string::npos) << detail;
  detail = expect_error(c.post_json("/api/v1/workers", json{{"version", "0.0.1"}, {"isa", fp.isa}, {"probe", fp.probe}}), 409);
  EXPECT_NE(detail.find("version"), std::string::npos) << detail;

  client::HttpReply reg = c.post_json("/api/v1/workers", json{{"name", "fake"}, {"version", fp.version}, {"isa", fp.isa},
                                                            {"probe", fp.probe}});
  ASSERT_EQ(reg.status, 201) << reg.body;
  const std::string w = "/api/v1/workers/" + std::to_string(reg.json()["id"].get<uint64_t>());
  EXPECT_EQ(c.post_json(w + "/lease?wait=0", json::object()).status, 204);
  EXPECT_EQ(c.post_json(w + "/lease?wait=nan", json::object(), 5).status, 204);
  expect_error(c.post_json(w + "/heartbeat", json{{"leases", json::array({json{{"id", "x"}}})}}), 400);
  expect_error(c.post_bytes(w + "/heartbeat", "[", "application/json"), 400);
  EXPECT_EQ(c.post_json(w + "/heartbeat", json{{"leases", json::array()}}).status, 200);

  JobSettings settings;
  settings.spp = 3;
  settings.width = 40;
  settings.height = 30;
  settings.tile_size = 16;
  uint64_t id = farm_.submit(cornell(), settings);
  ASSERT_GT(id, 0u);
  client::HttpReply lr = c.post_json(w + "/lease?wait=5", json::object());
  ASSERT_EQ(lr.status, 200) << lr.body;
  Lease lease;
  std::string error;
  ASSERT_TRUE(lease_from_json(lr.json(), lease, error)) << error;

  // Render the unit for real, then break it in every way.
  auto abs = std::filesystem::absolute(cornell());
  LoadedJobScene scene = load_job_scene(abs.parent_path().string(), abs.filename().string(), lease.settings, /*confine=*/false);
  TileResult result = render_lease(*scene.loaded.scene, lease);
  const std::string bytes = encode_tile_result(result);
  const std::string upload = w + "/results?lease=" + std::to_string(lease.id);
  auto post = [&](const std::string& b) { return c.post_bytes(upload, b, "application/x-tessera-tile"); };
  expect_error(post(bytes.substr(0, bytes.size() / 2)), 400);
  std::string flipped = bytes;
  flipped[flipped.size() / 2] ^= 0x40;
  expect_error(post(flipped), 400);
  expect_error(post(noise(1000, 3)), 400);
  TileResult wrong = result;
  wrong.sample_end += 1;
  expect_error(post(encode_tile_result(wrong)), 400);
  TileResult other_job = result;
  other_job.job_id = 4242;
  expect_error(post(encode_tile_result(other_job)), 404);

  client::HttpReply ok = post(bytes);
  ASSERT_EQ(ok.status, 200) << ok.body;
  EXPECT_EQ(ok.json()["accepted"], true);
  // The same worker sending it again (its answer lost): answered as the first time, not counted.
  client::HttpReply again = post(bytes);
  ASSERT_EQ(again.status, 200) << again.body;
  EXPECT_EQ(again.json()["accepted"], true);
  EXPECT_EQ(again.json()["duplicate"], false);
  json st = farm_.status(id);
  EXPECT_EQ(st["units_done"], 1);
  EXPECT_EQ(st["duplicate_results"], 0);

  // Failing the job's work on every worker there is fails the job, with the reason.
  for (int i = 0; i < 3; ++i) {
    client::HttpReply l = c.post_json(w + "/lease?wait=5", json::object());
    if (l.status != 200) break;
    (void)c.post_json(w + "/leases/" + std::to_string(l.json()["id"].get<uint64_t>()) + "/fail",
                      json{{"error", "out of memory on purpose"}});
  }
  st = farm_.status(id);
  EXPECT_EQ(st["state"], "failed");
  EXPECT_NE(st.value("error", "").find("out of memory on purpose"), std::string::npos) << st.dump(2);
}

// /metrics in Prometheus text format, consistent with the job it watched.
TEST(FarmServing, MetricsAgreeWithTheJob) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm;
  farm.start_server();
  farm.add_worker();
  ASSERT_TRUE(farm.wait_workers(1));
  JobSettings s;
  s.spp = 5;
  s.width = 48;
  s.height = 32;
  s.tile_size = 16;
  uint64_t id = farm.submit(cornell(), s);
  json st = farm.wait_job(id);
  ASSERT_EQ(st["state"], "done");
  client::HttpReply r = farm.client().get("/metrics");
  ASSERT_EQ(r.status, 200);
  std::map<std::string, double> values;
  std::istringstream in(r.body);
  int samples = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    // name{labels} value: every sample line must parse.
    size_t space = line.rfind(' ');
    ASSERT_NE(space, std::string::npos) << line;
    std::string key = line.substr(0, space);
    ASSERT_TRUE(std::isalpha(static_cast<unsigned char>(key[0]))) << line;
    values[key] = std::stod(line.substr(space + 1));
    ++samples;
  }
  const double units = st["units_total"].get<double>();
  EXPECT_EQ(values["tessera_jobs{state=\"done\"}"], 1);
  EXPECT_EQ(values["tessera_jobs{state=\"running\"}"], 0);
  EXPECT_EQ(values["tessera_passes_total{event=\"done\"}"], units);
  EXPECT_EQ(values["tessera_passes_total{event=\"leased\"}"], units);
  EXPECT_EQ(values["tessera_upload_seconds_count"], units);
  EXPECT_EQ(values["tessera_upload_seconds_bucket{le=\"+Inf\"}"], units);
  // Lease polls: at least the first; later leases come with the worker's results.
  EXPECT_GE(values["tessera_lease_wait_seconds_count"], 1);
  // Every lease and every result went through the group commit, in fewer commits than records.
  EXPECT_GE(values["tessera_store_records_total"], 2 * units);
  EXPECT_GE(values["tessera_store_commits_total{result=\"committed\"}"], 1);
  EXPECT_EQ(values["tessera_store_commits_total{result=\"failed\"}"], 0);
  EXPECT_EQ(values["tessera_workers{state=\"idle\"}"] + values["tessera_workers{state=\"busy\"}"], 1);
  EXPECT_GE(values["tessera_bytes_total{direction=\"in\"}"], st["result_bytes"].get<double>());
  EXPECT_GT(values["tessera_bytes_total{direction=\"out\"}"], 0);
  EXPECT_GT(values["tessera_worker_samples_per_second{worker=\"1\",name=\"w0\"}"], 0);
  std::printf("%d samples in /metrics\n", samples);
}

TEST(FarmServing, WaitingWorkersNeverStarveClients) {
  // 8 HTTP threads; 200 workers long-polling at once. At most half the threads may wait, so the
  // client calls below are answered while the polls are still open.
  constexpr int kPollers = 200;
  Farm farm({"--http-threads", "8", "--max-poll-wait", "8"});
  farm.start_server();
  auto c = farm.client();
  const BuildFingerprint& fp = build_fingerprint();
  std::vector<std::string> paths;
  for (int i = 0; i < kPollers; ++i) {
    client::HttpReply reg = c.post_json("/api/v1/workers", json{{"name", "poller" + std::to_string(i)},
                                                              {"version", fp.version}, {"isa", fp.isa}, {"probe", fp.probe}});
    ASSERT_EQ(reg.status, 201);
    paths.push_back("/api/v1/workers/" + std::to_string(reg.json()["id"].get<uint64_t>()) + "/lease?wait=8");
  }
  std::atomic<int> answered{0}, waited{0};
  std::vector<std::thread> pollers;
  for (const auto& p : paths)
    pollers.emplace_back([&, p] {
      auto t0 = std::chrono::steady_clock::now();
      client::HttpReply r = c.post_json(p, json::object(), 20);
      answered += r.status == 204;
      if (r.status != 204)
        std::printf("poll: %s after %.2f s\n", r.describe().c_str(),
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      waited += std::chrono::steady_clock::now() - t0 > std::chrono::seconds(4);
    });
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  // Bounded client timeouts (3 s, well under the polls' 8 s): these fail if the pool is pinned.
  EXPECT_TRUE(c.get("/healthz", 3).ok());
  EXPECT_TRUE(c.get("/api/v1/jobs", 3).ok());
  EXPECT_EQ(c.post_bytes("/api/v1/jobs", "{", "application/json", 3).status, 400);
  for (auto& t : pollers) t.join();
  EXPECT_EQ(answered.load(), kPollers) << "every poll ends with 204 (no work)";
  if (answered.load() != kPollers) std::system(("tail -20 " + farm.log("server")).c_str());
  EXPECT_GE(waited.load(), 1) << "some polls really waited";
  EXPECT_LE(waited.load(), 4) << "at most half of the 8 threads hold long polls";
}

}  // namespace
}  // namespace tessera::test
