// The attack suite: a running coordinator (tokens on, tight limits) with one finished and one
// accepted job is attacked every way the issue names: wrong tokens, oversized bodies, zip-slip,
// symlink and hard-link bundles, a bundle that unpacks to 1000x its size, too many files,
// absurd settings, a flood of jobs, slow-loris connections, and random bytes to every endpoint
// and to the socket. Every attack must be refused; afterwards the server is healthy, the
// finished job's image is unchanged and the accepted job renders bit-identically to a local render.
#include "archive_builder.h"
#include "farm_harness.h"
#include "raw_http.h"
#include "tessera/farm/build_fingerprint.h"

#include <atomic>
#include <random>

namespace tessera::test {
namespace {

using nlohmann::json;

constexpr const char* kClient = "client-attack-5c1e";
constexpr const char* kWorker = "worker-attack-0d42";

std::string cornell() { return shared_path("scenes/cornell-box/scene.xml"); }

// Counts attacks and refusals, and says which attack got through.
struct Tally {
  int attacks = 0, refused = 0;
  void expect_refused(bool refused_now, const std::string& what) {
    ++attacks;
    refused += refused_now;
    EXPECT_TRUE(refused_now) << "accepted: " << what;
  }
};

bool is_refusal(int status) { return status >= 400 && status < 500; }

std::string tgz(const std::string& name, const std::string& data) {
  return ArchiveBuilder(ArchiveBuilder::Format::TarGz).file(name, data).finish();
}

const char* kXml = "<scene version=\"0.6.0\"><shape type=\"sphere\"/></scene>";

TEST(FarmAttack, EveryAttackIsRefusedAndAcceptedWorkSurvives) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm({"--client-token", kClient, "--worker-token", kWorker, "--max-upload", "2000000", "--max-unpacked",
             "67108864", "--max-files", "50", "--max-spp", "4096", "--max-resolution", "4096", "--max-tiles", "20000",
             "--max-active-jobs", "3", "--header-timeout", "1.5", "--http-threads", "8", "--lease-timeout", "2"});
  farm.set_tokens(kClient, kWorker);
  farm.start_server();
  const farm::FarmClient client = farm.client();
  const farm::FarmClient worker_client(farm.url(), kWorker);
  const int port = farm.port();

  // Before: job B rendered to the end, job A accepted and waiting for a worker.
  JobSettings s;
  s.spp = 8;
  s.width = 48;
  s.height = 36;
  s.tile_size = 16;
  farm.add_worker();
  const uint64_t b = farm.submit(cornell(), s);
  ASSERT_GT(b, 0u);
  ASSERT_EQ(farm.wait_job(b).value("state", ""), "done");
  ASSERT_EQ(farm.worker(0).terminate(), 0);
  const std::string image_b = client.get("/api/v1/jobs/" + std::to_string(b) + "/image?format=exr").body;
  s.seed = 7;
  const uint64_t a = farm.submit(cornell(), s);
  ASSERT_GT(a, 0u);

  Tally tally;
  // 1. Tokens: none, a guess, the other role's.
  for (const char* path : {"/api/v1/jobs", "/metrics", "/api/v1/workers"}) {
    for (const std::string token : {"", "guess", kWorker})
      tally.expect_refused(farm::FarmClient(farm.url(), token).get(path).status == 401, std::string(path) + " with '" + token + "'");
  }
  tally.expect_refused(farm::FarmClient(farm.url(), kClient).post_json("/api/v1/workers", json::object()).status == 401,
                       "a client registering as a worker");

  // 2. Oversized bodies: a bundle over --max-upload, a body over the transport's limit.
  tally.expect_refused(client.post_bytes("/api/v1/scenes", noise(2100000, 1), "application/gzip").status == 413,
                       "bundle over --max-upload");
  tally.expect_refused(is_refusal(client.post_bytes("/api/v1/jobs", std::string(40u << 20, '{'), "application/json", 60).status),
                       "40 MB JSON body");

  // 3. Hostile bundles.
  const std::vector<std::pair<std::string, std::string>> bundles = {
      {"zip-slip ../", ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("scene.xml", kXml).file("../../evil", "x").finish()},
      {"zip-slip absolute", ArchiveBuilder(ArchiveBuilder::Format::Zip).file("scene.xml", kXml).file("/tmp/evil", "x").finish()},
      {"symlink out", ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("scene.xml", kXml).symlink("m.obj", "/etc/passwd").finish()},
      {"hard link out", ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("scene.xml", kXml).hardlink("m.obj", "/etc/passwd").finish()},
      {"device", ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("scene.xml", kXml).char_device("null").finish()},
      {"1000x bomb", tgz("scene.xml", std::string(100u << 20, ' '))},
      {"random bytes", noise(50000, 2)},
  };
  {
    ArchiveBuilder many(ArchiveBuilder::Format::TarGz);
    for (int i = 0; i < 60; ++i) many.file("f" + std::to_string(i), "x");
    const std::string files = many.finish();
    for (const auto& [what, bundle] : bundles) {
      tally.expect_refused(client.post_bytes("/api/v1/scenes", bundle, "application/gzip").status == 400, what);
      tally.expect_refused(client.post_job_with_bundle(json::object(), bundle).status == 400, what + " with a job");
    }
    tally.expect_refused(client.post_bytes("/api/v1/scenes", files, "application/gzip").status == 400, "60 files");
    std::printf("bomb bundle: %zu bytes for %u unpacked\n", bundles[5].second.size(), 100u << 20);
  }

  // 4. Absurd settings (the scene is fine; the limits are the server's flags).
  const std::string scene_ok = tgz("scene.xml", kXml);
  for (const json& bad : {json{{"spp", 100000}}, json{{"width", 100000}, {"height", 10}}, json{{"width", 4096}, {"height", 4096}, {"tile_size", 4}},
                          json{{"tile_size", 2}}, json{{"spp", -1}}, json{{"seed", "x"}}, json{{"defines", 3}}})
    tally.expect_refused(is_refusal(client.post_job_with_bundle(bad, scene_ok).status), "settings " + bad.dump());

  // 5. A flood of jobs: --max-active-jobs 3 holds A and two more.
  std::vector<uint64_t> flood;
  for (int i = 0; i < 6; ++i) {
    farm::HttpReply r = client.post_job_with_bundle(json{{"spp", 1}, {"width", 8}, {"height", 8}}, scene_ok);
    if (r.status == 201) flood.push_back(r.json()["id"].get<uint64_t>());
    else tally.expect_refused(r.status == 429, "job beyond --max-active-jobs");
  }
  EXPECT_EQ(flood.size(), 2u);
  for (uint64_t id : flood) EXPECT_TRUE(client.del("/api/v1/jobs/" + std::to_string(id)).ok());

  // 6. Slow-loris: more trickling connections than HTTP threads. Each must be cut by the server
  // (not by us giving up after 20 s), and a real client is answered meanwhile.
  {
    constexpr int kSlow = 16;
    std::atomic<int> cut{0};
    std::vector<double> seconds(kSlow, 0);
    std::vector<std::thread> slow;
    for (int i = 0; i < kSlow; ++i)
      slow.emplace_back([&, i] {
        RawConnection c(port);
        const auto t0 = std::chrono::steady_clock::now();
        bool alive = c.connected() && c.send("GET /healthz HTTP/1.1\r\nHost: x\r\n");
        const auto give_up = t0 + std::chrono::seconds(20);
        while (alive && std::chrono::steady_clock::now() < give_up) {
          if (c.closed_within(0.25)) break;
          alive = c.send("X-Slow: 1\r\n");
        }
        seconds[size_t(i)] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        cut += std::chrono::steady_clock::now() < give_up;
      });
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    EXPECT_TRUE(client.get("/healthz", 15).ok()) << "a client is answered during the attack";
    for (auto& t : slow) t.join();
    for (int i = 0; i < kSlow; ++i) tally.expect_refused(seconds[size_t(i)] < 20, "slow-loris connection " + std::to_string(i));
    std::printf("slow-loris: %d of %d connections cut, after %.1f..%.1f s\n", cut.load(), kSlow,
                *std::min_element(seconds.begin(), seconds.end()), *std::max_element(seconds.begin(), seconds.end()));
  }

  // 7. Random bytes as the body of every endpoint (with the right token), and as the request itself.
  {
    const BuildFingerprint& fp = build_fingerprint();
    farm::HttpReply reg = worker_client.post_json(
        "/api/v1/workers", json{{"name", "fuzz"}, {"version", fp.version}, {"isa", fp.isa}, {"probe", fp.probe}});
    ASSERT_EQ(reg.status, 201) << reg.body;
    const std::string w = "/api/v1/workers/" + std::to_string(reg.json()["id"].get<uint64_t>());
    struct Endpoint {
      std::string method, path;
      bool worker;
    };
    const std::vector<Endpoint> endpoints = {
        {"POST", "/api/v1/jobs", false},         {"POST", "/api/v1/scenes", false},
        {"PATCH", "/api/v1/jobs/999", false},    {"DELETE", "/api/v1/jobs/999", false},
        {"POST", "/api/v1/jobs/999/retry", false}, {"POST", "/api/v1/workers/999/drain", false},
        {"POST", "/api/v1/workers", true},       {"POST", w + "/heartbeat", true},
        {"POST", w + "/results", true},          {"POST", w + "/leases/999/fail", true},
        {"DELETE", "/api/v1/workers/999", true},
    };
    std::mt19937 rng(11);
    int sent = 0;
    for (const Endpoint& e : endpoints)
      for (size_t n : {size_t(1), size_t(100), size_t(10000)}) {
        const int status = raw_status(port, raw_request(e.method, e.path, e.worker ? kWorker : kClient, noise(n, rng())));
        tally.expect_refused(is_refusal(status), e.method + " " + e.path + " with " + std::to_string(n) + " random bytes: " +
                                                     std::to_string(status));
        ++sent;
      }
    // (In parallel: garbage without a line end waits for the header timeout.)
    std::vector<int> garbage(20, -1);
    std::vector<std::thread> senders;
    for (size_t i = 0; i < garbage.size(); ++i)
      senders.emplace_back([&, i, seed = uint32_t(rng())] { garbage[i] = raw_status(port, noise(size_t(1) << (i % 16), seed), 10); });
    for (auto& t : senders) t.join();
    for (int status : garbage)
      tally.expect_refused(status == 0 || is_refusal(status), "random bytes as a request: " + std::to_string(status));
    // Lies about the body, headers over httplib's limits, a path out of the API.
    tally.expect_refused(raw_status(port, "POST /api/v1/jobs HTTP/1.1\r\nAuthorization: Bearer " + std::string(kClient) +
                                              "\r\nContent-Length: 100000\r\n\r\nshort", 5) != 201, "lying Content-Length");
    tally.expect_refused(is_refusal(raw_status(port, "GET /healthz HTTP/1.1\r\nX-Big: " + std::string(20000, 'a') + "\r\n\r\n")) ||
                             raw_status(port, "GET /healthz HTTP/1.1\r\nX-Big: " + std::string(20000, 'a') + "\r\n\r\n") == 0,
                         "a 20 kB header");
    tally.expect_refused(is_refusal(raw_status(port, raw_request("GET", "/api/v1/scenes/../../../etc/passwd", kClient, ""))),
                         "a path out of the API");
    std::printf("random bodies: %d requests to %zu endpoints\n", sent, endpoints.size());
  }

  // After: healthy; no job was created by any attack; B unchanged; A renders right once a worker joins.
  EXPECT_TRUE(client.get("/healthz", 5).ok());
  json jobs = client.get("/api/v1/jobs").json();
  ASSERT_TRUE(jobs.is_object()) << "job list";
  EXPECT_EQ(jobs["jobs"].size(), 2u + flood.size()) << jobs.dump();
  EXPECT_EQ(client.get("/api/v1/jobs/" + std::to_string(b) + "/image?format=exr").body, image_b);
  farm.add_worker();
  ASSERT_EQ(farm.wait_job(a).value("state", ""), "done");
  EXPECT_EQ(differing_pixels(farm.image(a), local_render(cornell(), s)), 0);
  std::printf("attack suite: %d attacks, %d refused; server healthy, accepted jobs intact\n", tally.attacks, tally.refused);
  EXPECT_EQ(tally.refused, tally.attacks);
}

}  // namespace
}  // namespace tessera::test
