// TLS: the coordinator serves https with --tls-cert/--tls-key; workers and `tessera submit` verify
// it (--ca-file), refuse a server they cannot verify, and render the same bits as over http.
#include "farm_harness.h"

#include <cstdlib>
#include <fstream>
#include <map>

namespace tessera::test {
namespace {

// A self-signed certificate for 127.0.0.1 (made with the openssl command, as an operator would).
bool make_certificate(const TempDir& dir, const std::string& name) {
  const std::string base = (dir.path / name).string();
  const std::string cmd = "openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj /CN=127.0.0.1 "
                          "-addext subjectAltName=IP:127.0.0.1 -keyout " + base + ".key -out " + base + ".pem > " +
                          base + "-openssl.txt 2>&1";
  return std::system(cmd.c_str()) == 0;
}

TEST(FarmTls, WorkersAndClientsVerifyTheServer) {
  TESSERA_REQUIRE_FILE(cornell());
  Farm farm({"--client-token", "c-tls", "--worker-token", "w-tls", "--log-format", "json", "--log-level", "debug"});
  ASSERT_TRUE(make_certificate(farm.dir(), "server")) << "the openssl command is needed (scripts/install-deps.sh)";
  ASSERT_TRUE(make_certificate(farm.dir(), "other"));
  const std::string cert = (farm.dir().path / "server.pem").string(), key = (farm.dir().path / "server.key").string();
  farm.use_tls(cert, key, cert);
  farm.set_tokens("c-tls", "w-tls");
  farm.start_server();
  ASSERT_EQ(farm.url().rfind("https://", 0), 0u);

  // Plain http to the https port gets no HTTP answer; https without the right CA is refused.
  const std::string host = "127.0.0.1:" + std::to_string(farm.port());
  EXPECT_EQ(client::FarmClient("http://" + host, "c-tls").get("/healthz", 5).status, 0);
  EXPECT_EQ(client::FarmClient("https://" + host, "c-tls").get("/healthz", 5).status, 0) << "verified against system CAs";
  client::HttpReply wrong_ca = client::FarmClient("https://" + host, "c-tls", (farm.dir().path / "other.pem").string()).get("/healthz", 5);
  EXPECT_EQ(wrong_ca.status, 0);
  std::printf("wrong CA: %s\n", wrong_ca.describe().c_str());

  farm.add_worker(2);
  ASSERT_TRUE(farm.wait_workers(1));
  JobSettings s;
  s.spp = 6;
  s.width = 40;
  s.height = 30;
  s.tile_size = 16;
  const uint64_t id = farm.submit(cornell(), s);
  ASSERT_GT(id, 0u);
  ASSERT_EQ(farm.wait_job(id).value("state", ""), "done");
  EXPECT_EQ(differing_pixels(farm.image(id), local_render(cornell(), s)), 0);

  // `tessera submit` over https: with --ca-file it works; without, it refuses the server.
  const std::string out = (farm.dir().path / "tls.png").string(), log = farm.log("submit");
  const std::string cmd = "TESSERA_CLIENT_TOKEN=c-tls " + std::string(TESSERA_CLI_BIN) + " submit " + cornell() +
                          " --server " + farm.url() + " --spp 2 --width 32 --height 24 -q";
  EXPECT_EQ(std::system((cmd + " --ca-file " + cert + " -o " + out + " > " + log + " 2>&1").c_str()), 0);
  EXPECT_TRUE(std::filesystem::exists(out));
  EXPECT_NE(std::system((cmd + " > " + log + " 2>&1").c_str()), 0);

  // --log-format json: every line of the server's log is one JSON object; the job's life is
  // there as events carrying its id, and every lease it issued.
  std::ifstream in(farm.log("server"));
  std::map<std::string, int> events;
  int lines = 0;
  for (std::string line; std::getline(in, line);) {
    ++lines;
    nlohmann::json j = nlohmann::json::parse(line, nullptr, false);
    ASSERT_TRUE(j.is_object() && j.contains("time") && j.contains("level")) << line;
    if (j.value("job", uint64_t(0)) == id) ++events[j.value("event", "")];
  }
  EXPECT_GT(lines, 0);
  EXPECT_EQ(events["job.submitted"], 1);
  EXPECT_EQ(events["job.started"], 1);
  EXPECT_EQ(events["job.done"], 1);
  const int units = farm.status(id).value("units_total", 0);
  EXPECT_GT(units, 0);
  EXPECT_EQ(events["lease.issued"], units);
  EXPECT_EQ(events["lease.done"], units);
}

}  // namespace
}  // namespace tessera::test
