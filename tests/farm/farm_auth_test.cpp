// Bearer tokens: every API call needs the right one, a missing or wrong token is a 401 that says
// nothing else, /healthz stays open, and workers and `tessera submit` that carry the tokens work.
#include "farm_harness.h"
#include "tessera/farm/build_fingerprint.h"

namespace tessera::test {
namespace {

using nlohmann::json;

constexpr const char* kClient = "client-secret-7f3a";
constexpr const char* kWorker = "worker-secret-91bd";

struct Call {
  std::string method, path;
  bool worker;  // needs the worker token (else the client token)
};

client::HttpReply send(const client::FarmClient& c, const Call& call) {
  if (call.method == "GET") return c.get(call.path, 5);
  if (call.method == "DELETE") return c.del(call.path, json::object(), 5);
  return c.post_bytes(call.path, std::string(4096, 'x'), "application/octet-stream", 10);
}

TEST(FarmAuth, EveryCallNeedsTheRightToken) {
  Farm farm({"--client-token", kClient, "--worker-token", kWorker});
  farm.set_tokens(kClient, kWorker);
  farm.start_server();
  const std::string hash(64, 'a');
  const std::vector<Call> calls = {
      {"GET", "/api/v1/jobs", false},           {"POST", "/api/v1/jobs", false},
      {"GET", "/api/v1/jobs/1", false},         {"GET", "/api/v1/jobs/1/image?format=png", false},
      {"DELETE", "/api/v1/jobs/1", false},      {"POST", "/api/v1/scenes", false},
      {"GET", "/api/v1/workers", false},        {"GET", "/api/v1/nothing", false},
      {"POST", "/api/v1/workers", true},        {"POST", "/api/v1/workers/1/lease?wait=0", true},
      {"POST", "/api/v1/workers/1/heartbeat", true}, {"POST", "/api/v1/workers/1/results", true},
      {"POST", "/api/v1/workers/1/leases/1/fail", true}, {"DELETE", "/api/v1/workers/1", true},
      {"GET", "/api/v1/scenes/" + hash, true},        {"GET", "/metrics", false},
  };
  const client::FarmClient none(farm.url()), wrong(farm.url(), "guess"), client_side(farm.url(), kClient),
      worker(farm.url(), kWorker);
  int refused = 0;
  for (const Call& call : calls) {
    SCOPED_TRACE(call.method + " " + call.path);
    const client::FarmClient& other = call.worker ? client_side : worker;
    for (const client::FarmClient* c : {&none, &wrong, &other}) {
      if (call.path.rfind("/api/v1/scenes/", 0) == 0 && c == &other) continue;  // either token may download
      client::HttpReply r = send(*c, call);
      EXPECT_EQ(r.status, 401) << r.body;
      EXPECT_EQ(r.json().value("error", ""), "unauthorized");
      EXPECT_EQ(r.body.find("secret"), std::string::npos) << "the reply leaks a token";
      EXPECT_EQ(r.headers.count("WWW-Authenticate"), 1u);
      refused += r.status == 401;
    }
    // The right token gets past the check (whatever the call itself then says).
    EXPECT_NE(send(call.worker ? worker : client_side, call).status, 401);
  }
  std::printf("refused %d unauthorised calls\n", refused);
  EXPECT_TRUE(none.get("/healthz").ok()) << "health checks need no token";
  // The dashboard's page and files are open (they hold no data); what the page asks for is not.
  // So is the API description (docs/openapi.json).
  for (const char* path : {"/", "/ui/app.js", "/ui/style.css", "/api/v1/openapi.json"}) {
    client::HttpReply page = none.get(path, 5);
    EXPECT_EQ(page.status, 200) << path;
    EXPECT_FALSE(page.body.empty()) << path;
  }
  EXPECT_NE(none.get("/", 5).body.find("<title>Tessera farm</title>"), std::string::npos);
  EXPECT_EQ(none.get("/api/v1/openapi.json", 5).json().value("openapi", ""), "3.1.0");
  EXPECT_EQ(none.get("/api/v1/jobs", 5).status, 401) << "the dashboard opens the page, not the API";
  EXPECT_EQ(none.post_bytes("/", "x", "text/plain", 5).status, 401) << "only GET is open";
}

TEST(FarmAuth, WorkersAndTheClientCarryTheirTokens) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm({"--client-token", kClient, "--worker-token", kWorker});
  farm.set_tokens(kClient, kWorker);
  farm.start_server();
  farm.add_worker();  // TESSERA_WORKER_TOKEN in its environment
  ASSERT_TRUE(farm.wait_workers(1));
  JobSettings s;
  s.spp = 4;
  s.width = 40;
  s.height = 30;
  uint64_t id = farm.submit(cornell(), s);
  ASSERT_GT(id, 0u);
  EXPECT_EQ(farm.wait_job(id).value("state", ""), "done");

  // `tessera submit` reads TESSERA_CLIENT_TOKEN; without it the server refuses and it says so.
  const std::string out = (farm.dir().path / "c.exr").string(), log = farm.log("submit");
  const std::string cmd = std::string(TESSERA_CLI_BIN) + " submit " + cornell() + " --server " + farm.url() +
                          " --spp 2 --width 32 --height 24 -q -o " + out + " > " + log + " 2>&1";
  EXPECT_EQ(std::system(("TESSERA_CLIENT_TOKEN=" + std::string(kClient) + " " + cmd).c_str()), 0);
  EXPECT_TRUE(std::filesystem::exists(out));
  EXPECT_NE(std::system(("env -u TESSERA_CLIENT_TOKEN " + cmd).c_str()), 0);
  // A token file works too.
  const std::string token_file = farm.dir().write("client.token", std::string(kClient) + "\n");
  EXPECT_EQ(std::system((std::string(TESSERA_CLI_BIN) + " jobs --server " + farm.url() + " --token-file " + token_file +
                         " > " + log + " 2>&1").c_str()),
            0);

  // A worker with a wrong token is refused at registration and exits with the reason.
  Child stranger({TESSERA_WORKER_BIN, "--server", farm.url(), "--cache-dir", (farm.dir().path / "s").string()},
                 farm.log("stranger"), {"TESSERA_WORKER_TOKEN=nope"});
  EXPECT_EQ(stranger.wait_exit(20), 3);
}

}  // namespace
}  // namespace tessera::test
