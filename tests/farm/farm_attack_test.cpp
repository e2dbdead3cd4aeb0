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
#include "tessera/farm/sha256.h"
#include "tessera/farm/tile_result.h"

#include <atomic>
#include <csignal>
#include <random>

namespace tessera::test {
namespace {

using nlohmann::json;

constexpr const char* kClient = "client-attack-5c1e";
constexpr const char* kWorker = "worker-attack-0d42";

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
             "--max-active-jobs", "3", "--header-timeout", "1.5", "--http-threads", "8", "--heartbeat-interval", "0.7"});
  farm.set_tokens(kClient, kWorker);
  farm.start_server();
  const client::FarmClient http = farm.client();
  const client::FarmClient worker_client(farm.url(), kWorker);
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
  const std::string image_b = http.get("/api/v1/jobs/" + std::to_string(b) + "/image?format=exr").body;
  s.seed = 7;
  const uint64_t a = farm.submit(cornell(), s);
  ASSERT_GT(a, 0u);

  Tally tally;
  // 1. Tokens: none, a guess, the other role's.
  for (const char* path : {"/api/v1/jobs", "/metrics", "/api/v1/workers"}) {
    for (const std::string token : {"", "guess", kWorker})
      tally.expect_refused(client::FarmClient(farm.url(), token).get(path).status == 401, std::string(path) + " with '" + token + "'");
  }
  tally.expect_refused(client::FarmClient(farm.url(), kClient).post_json("/api/v1/workers", json::object()).status == 401,
                       "a client registering as a worker");

  // 2. Oversized bodies: a bundle over --max-upload, a body over the transport's limit.
  tally.expect_refused(http.post_bytes("/api/v1/scenes", noise(2100000, 1), "application/gzip").status == 413,
                       "bundle over --max-upload");
  // (Refused from its headers and closed unread: the client may meet the closed connection, 0,
  // before it reads the 413. Its write must then not end this test with a SIGPIPE.)
  ::signal(SIGPIPE, SIG_IGN);
  const int json_40mb = http.post_bytes("/api/v1/jobs", std::string(40u << 20, '{'), "application/json", 60).status;
  tally.expect_refused(is_refusal(json_40mb) || json_40mb == 0, "40 MB JSON body");

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
      tally.expect_refused(http.post_bytes("/api/v1/scenes", bundle, "application/gzip").status == 400, what);
      tally.expect_refused(client::FarmApi(http).submit_job(json::object(), bundle).status == 400, what + " with a job");
    }
    tally.expect_refused(http.post_bytes("/api/v1/scenes", files, "application/gzip").status == 400, "60 files");
    std::printf("bomb bundle: %zu bytes for %u unpacked\n", bundles[5].second.size(), 100u << 20);
  }

  // 4. Absurd settings (the scene is fine; the limits are the server's flags).
  const std::string scene_ok = tgz("scene.xml", kXml);
  for (const json& bad : {json{{"spp", 100000}}, json{{"width", 100000}, {"height", 10}}, json{{"width", 4096}, {"height", 4096}, {"tile_size", 4}},
                          json{{"tile_size", 2}}, json{{"spp", -1}}, json{{"seed", "x"}}, json{{"defines", 3}}})
    tally.expect_refused(is_refusal(client::FarmApi(http).submit_job(bad, scene_ok).status), "settings " + bad.dump());

  // 5. A flood of jobs: --max-active-jobs 3 holds A and two more.
  std::vector<uint64_t> flood;
  for (int i = 0; i < 6; ++i) {
    client::HttpReply r = client::FarmApi(http).submit_job(json{{"spp", 1}, {"width", 8}, {"height", 8}}, scene_ok);
    if (r.status == 201) flood.push_back(r.json()["id"].get<uint64_t>());
    else tally.expect_refused(r.status == 429, "job beyond --max-active-jobs");
  }
  EXPECT_EQ(flood.size(), 2u);
  for (uint64_t id : flood) EXPECT_TRUE(http.del("/api/v1/jobs/" + std::to_string(id)).ok());

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
    EXPECT_TRUE(http.get("/healthz", 15).ok()) << "a client is answered during the attack";
    for (auto& t : slow) t.join();
    for (int i = 0; i < kSlow; ++i) tally.expect_refused(seconds[size_t(i)] < 20, "slow-loris connection " + std::to_string(i));
    std::printf("slow-loris: %d of %d connections cut, after %.1f..%.1f s\n", cut.load(), kSlow,
                *std::min_element(seconds.begin(), seconds.end()), *std::max_element(seconds.begin(), seconds.end()));
  }

  // 7. Random bytes as the body of every endpoint (with the right token), and as the request itself.
  {
    const BuildFingerprint& fp = build_fingerprint();
    client::HttpReply reg = worker_client.post_json(
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
  EXPECT_TRUE(http.get("/healthz", 5).ok());
  json jobs = http.get("/api/v1/jobs").json();
  ASSERT_TRUE(jobs.is_object()) << "job list";
  EXPECT_EQ(jobs["jobs"].size(), 2u + flood.size()) << jobs.dump();
  EXPECT_EQ(http.get("/api/v1/jobs/" + std::to_string(b) + "/image?format=exr").body, image_b);
  farm.add_worker();
  ASSERT_EQ(farm.wait_job(a).value("state", ""), "done");
  EXPECT_EQ(differing_pixels(farm.image(a), local_render(cornell(), s)), 0);
  std::printf("attack suite: %d attacks, %d refused; server healthy, accepted jobs intact\n", tally.attacks, tally.refused);
  EXPECT_EQ(tally.refused, tally.attacks);
}

// No --max-unpacked, no --max-ratio: the defaults alone refuse a bundle that inflates 1000:1.
TEST(FarmAttack, DefaultLimitsRefuseACompressionBomb) {
  Farm farm({"--client-token", kClient, "--worker-token", kWorker});
  farm.set_tokens(kClient, kWorker);
  farm.start_server();
  const client::FarmClient http = farm.client();
  const std::string bomb = tgz("scene.xml", std::string(kXml) + std::string(200u << 20, ' '));
  ASSERT_LT(bomb.size(), 300000u);
  const client::HttpReply up = http.post_bytes("/api/v1/scenes", bomb, "application/gzip");
  EXPECT_EQ(up.status, 400) << up.body;
  EXPECT_NE(up.body.find("--max-ratio"), std::string::npos) << up.body;
  const client::HttpReply job = client::FarmApi(http).submit_job(json::object(), bomb);
  EXPECT_EQ(job.status, 400) << job.body;
  EXPECT_EQ(http.post_bytes("/api/v1/scenes", tgz("scene.xml", kXml), "application/gzip").status, 201);
  EXPECT_TRUE(http.get("/healthz", 5).ok());
  std::printf("bomb under default limits: %zu bytes for %u unpacked: %d %s\n", bomb.size(), 200u << 20, up.status,
              up.json().value("detail", "").c_str());
}

/// A request as curl writes it: `headers` verbatim ("Name: value\r\n" each), then the body.
std::string curl_like(const std::string& method, const std::string& path, const std::string& headers,
                      const std::string& body = "") {
  return method + " " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n" + headers + "\r\n" + body;
}

// What curl sends when a user types the docs' commands a little differently: the bearer scheme
// in another case, POSTs without a body (no Content-Length), a bundle with curl's default
// form Content-Type, and bodies over --max-upload. Each gets a proper answer at once.
TEST(FarmAttack, HttpEdgeCasesAreAnsweredProperly) {
  Farm farm({"--client-token", kClient, "--worker-token", kWorker, "--max-upload", "100000"});
  farm.set_tokens(kClient, kWorker);
  farm.start_server();
  const int port = farm.port();
  const std::string client_auth = "Authorization: Bearer " + std::string(kClient) + "\r\n";
  const std::string worker_auth = "Authorization: Bearer " + std::string(kWorker) + "\r\n";

  // The scheme is case-insensitive (RFC 7235); the token is not.
  for (const std::string scheme : {"bearer", "BEARER", "bEaReR"})
    EXPECT_EQ(raw_status(port, curl_like("GET", "/api/v1/jobs", "Authorization: " + scheme + " " + kClient + "\r\n")), 200)
        << scheme;
  const std::string client_token = kClient;
  for (const std::string& wrong : std::vector<std::string>{"bearer guess", "bearer " + std::string(kWorker), "bearer",
                                                           "bearer " + client_token.substr(1), "basic " + client_token})
    EXPECT_EQ(raw_status(port, curl_like("GET", "/api/v1/jobs", "Authorization: " + wrong + "\r\n")), 401) << wrong;

  // Bodiless POSTs (curl -X POST URL): answered by their handler, not after the read timeout.
  const BuildFingerprint& fp = build_fingerprint();
  const client::HttpReply reg = client::FarmClient(farm.url(), kWorker)
                                    .post_json("/api/v1/workers", json{{"name", "edge"}, {"version", fp.version},
                                                                       {"isa", fp.isa}, {"probe", fp.probe}});
  ASSERT_EQ(reg.status, 201) << reg.body;
  const std::string w = "/api/v1/workers/" + std::to_string(reg.json()["id"].get<uint64_t>());
  EXPECT_EQ(raw_status(port, curl_like("POST", "/api/v1/jobs/999/retry", client_auth), 5), 404);
  EXPECT_EQ(raw_status(port, curl_like("POST", w + "/lease?wait=1", worker_auth), 5), 204);
  EXPECT_EQ(raw_status(port, curl_like("POST", w + "/drain", client_auth), 5), 200);
  EXPECT_EQ(raw_status(port, curl_like("POST", w + "/lease?wait=1", worker_auth), 5), 410);

  // curl --data-binary's default Content-Type is a form's; the bundle's bytes are taken as they are.
  const std::string bundle = ArchiveBuilder(ArchiveBuilder::Format::TarGz).file("scene.xml", kXml).file("m.bin", noise(50000, 3)).finish();
  const client::FarmClient http = farm.client();
  const client::HttpReply as_form = http.post_bytes("/api/v1/scenes", bundle, "application/x-www-form-urlencoded");
  EXPECT_EQ(as_form.status, 201) << as_form.body;
  EXPECT_EQ(as_form.json().value("hash", ""), sha256_hex(bundle));

  // Every 413 names the limit and its flag: a bundle over --max-upload (the coordinator's check)
  // and a body over what is read at all (refused from its headers); a chunked body, whose size
  // the transport would not bound, is refused with 411.
  const client::HttpReply big = http.post_bytes("/api/v1/scenes", noise(200000, 4), "application/gzip");
  EXPECT_EQ(big.status, 413);
  EXPECT_NE(big.body.find("--max-upload"), std::string::npos) << big.body;
  // (The 413 comes from the headers alone: the body is never read, so none is sent.)
  const std::string huge =
      raw_reply(port, curl_like("POST", "/api/v1/scenes", client_auth + "Content-Length: " + std::to_string(17u << 20) + "\r\n"), 20);
  EXPECT_EQ(status_of(huge), 413) << huge;
  EXPECT_NE(huge.find("16877216 bytes (tessera-server --max-upload 100000"), std::string::npos) << huge;
  EXPECT_EQ(raw_status(port, curl_like("POST", "/api/v1/scenes", client_auth + "Transfer-Encoding: chunked\r\n", "5\r\nhello\r\n0\r\n\r\n"), 5),
            411);

  // Heartbeats that are not an object with a lease list.
  const client::FarmClient worker(farm.url(), kWorker);
  for (const char* junk : {"[]", "42", "\"x\"", "null", "{\"leases\": \"x\"}", "{\"leases\": [1]}", "{\"junk\": 1}",
                           "{\"leases\": [], \"junk\": 1}", "{\"leases\": [{\"id\": 1, \"job\": 1, \"tile\": 0}]}"})
    EXPECT_EQ(worker.post_bytes(w + "/heartbeat", junk, "application/json").status, 400) << junk;
  // 50 MB of junk in a heartbeat is refused before it is read (a message has at most 1 MiB). The
  // client's write then meets a closed socket: EPIPE, not a signal that would end this test.
  ::signal(SIGPIPE, SIG_IGN);
  const client::HttpReply junk_body = worker.post_bytes(w + "/heartbeat", std::string(50u << 20, ' '), "application/json", 20);
  // (The connection is closed unread, so the client may see the reset before the answer.)
  EXPECT_TRUE(junk_body.status == 413 || junk_body.status == 0) << junk_body.status << " " << junk_body.body;
  if (junk_body.status == 413) {
    EXPECT_NE(junk_body.body.find("at most 1048576"), std::string::npos) << junk_body.body;
  }
  EXPECT_TRUE(http.get("/healthz", 5).ok());
}

// Each kind of body has its own limit, named in the 413: a result may weigh what its unit's sums
// can (a 16x16 tile here: tens of kilobytes, not the 64 MiB the largest tile would need), and a
// result for a lease the coordinator does not hold what the largest unit's can.
TEST(FarmAttack, AResultOverWhatItsUnitCanWeighIsRefusedUnread) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm({"--client-token", kClient, "--worker-token", kWorker});
  farm.set_tokens(kClient, kWorker);
  farm.start_server();
  const int port = farm.port();
  JobSettings s;
  s.spp = 4;
  s.width = 32;
  s.height = 32;
  s.tile_size = 16;
  ASSERT_GT(farm.submit(cornell(), s), 0u);
  const client::FarmClient worker(farm.url(), kWorker);
  const BuildFingerprint& fp = build_fingerprint();
  const client::HttpReply reg =
      worker.post_json("/api/v1/workers", json{{"name", "w"}, {"version", fp.version}, {"isa", fp.isa}, {"probe", fp.probe}});
  ASSERT_EQ(reg.status, 201) << reg.body;
  const std::string w = "/api/v1/workers/" + std::to_string(reg.json()["id"].get<uint64_t>());
  const client::HttpReply lease = worker.post_bytes(w + "/lease?wait=5", "", "application/json");
  ASSERT_EQ(lease.status, 200) << lease.body;
  const uint64_t id = lease.json()["id"].get<uint64_t>();
  const uint64_t limit = max_tile_result_bytes({0, 0, 16, 16}, false, false);
  ASSERT_LT(limit, uint64_t(1) << 20);
  const std::string auth = "Authorization: Bearer " + std::string(kWorker) + "\r\n";
  const std::string over = raw_reply(port, curl_like("POST", w + "/results?lease=" + std::to_string(id),
                                                     auth + "Content-Length: " + std::to_string(2u << 20) + "\r\n"), 5);
  EXPECT_EQ(status_of(over), 413) << over;
  EXPECT_NE(over.find("a result of lease " + std::to_string(id) + " (a 16x16 tile) may have at most " +
                      std::to_string(limit)), std::string::npos) << over;
  const std::string unknown = raw_reply(port, curl_like("POST", w + "/results?lease=999999",
                                                        auth + "Content-Length: 900000000\r\n"), 5);
  EXPECT_EQ(status_of(unknown), 413) << unknown;
  EXPECT_NE(unknown.find("a lease this coordinator does not hold (as much as the largest unit: a 1024x1024 tile with AOV "
                         "sums, training records and per-pixel state) may have at most " +
                         std::to_string(max_tile_result_bytes({0, 0, 1024, 1024}, true, true, true))),
            std::string::npos) << unknown;
  EXPECT_TRUE(farm.client().get("/healthz", 5).ok());
}

}  // namespace
}  // namespace tessera::test
