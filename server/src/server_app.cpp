#include "tessera/server/server_app.h"

#include "http_listener.h"
#include "response_recorder.h"
#include "event_log.h"
#include "local_workers.h"
#include "scene_planner.h"
#include "tessera/farm/protocol.h"

#include <spdlog/spdlog.h>

#include <malloc.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>

namespace tessera::server {

namespace fs = std::filesystem;

namespace {

// Memory and signals, before any thread starts.
void configure_process(sigset_t& signals) {
  // Buffers of 1 MiB and more (images being written or served, films) are mapped and given back
  // to the system when freed. Without a fixed threshold glibc raises it after the first large
  // free and serves later ones from per-thread heaps, which keep their peak: the coordinator's
  // resident memory then grows with every image it ever wrote (bench/coordinator_memory.sh).
  // Fixing it also fixes the trim threshold, whose 128 KiB default would hand heap tops back and
  // fault them in again for every tile result (+20% CPU per unit in bench/farm_load.sh).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  // Signals are taken synchronously by the main thread (sigtimedwait), so every other thread,
  // including httplib's, runs with them blocked.
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  ::signal(SIGPIPE, SIG_IGN);
}

// --listen HOST:PORT; false (with a message) when it is not.
bool parse_listen(const std::string& listen, std::string& host, int& port) {
  const size_t colon = listen.rfind(':');
  if (colon == std::string::npos) {
    std::fprintf(stderr, "tessera-server: --listen '%s': expected HOST:PORT\n", listen.c_str());
    return false;
  }
  host = listen.substr(0, colon);
  try {
    port = std::stoi(listen.substr(colon + 1));
  } catch (const std::exception&) {
    std::fprintf(stderr, "tessera-server: --listen '%s': bad port\n", listen.c_str());
    return false;
  }
  return true;
}

// Logging and tokens; false (with a message) on a bad setting.
bool configure_access(const ServerOptions& o, const std::string& host, AuthTokens& tokens) {
  try {
    configure_logging(o.log_format, o.log_level);
    tokens.client = resolve_token(o.client_token, o.client_token_file, "TESSERA_CLIENT_TOKEN");
    tokens.worker = resolve_token(o.worker_token, o.worker_token_file, "TESSERA_WORKER_TOKEN");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera-server: %s\n", e.what());
    return false;
  }
  if (!tokens.enabled() && host != "127.0.0.1" && host != "localhost" && host != "::1")
    spdlog::warn("no client or worker token: anyone who can reach {} can use this farm", o.listen);
  return true;
}

std::unique_ptr<Coordinator> open_coordinator(const ServerOptions& o) {
  try {
    CoordinatorOptions copt = o.coordinator;
    // This very program plans scenes in a child (`--plan-scene`): the coordinator's memory stays
    // that of its bookkeeping, however large the scenes submitted.
    std::error_code ec;
    if (copt.scene_planner.empty()) copt.scene_planner = fs::read_symlink("/proc/self/exe", ec).string();
    return std::make_unique<Coordinator>(copt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera-server: cannot use data directory '%s': %s\n", o.coordinator.data_dir.c_str(), e.what());
    return nullptr;
  }
}

}  // namespace

int run_scene_planner_main() { return run_scene_planner(stdin, stdout); }

int run_server(const ServerOptions& o) {
  sigset_t signals;
  configure_process(signals);
  std::string host;
  int port = 0;
  AuthTokens tokens;
  if (!parse_listen(o.listen, host, port) || !configure_access(o, host, tokens)) return 2;
  std::unique_ptr<Coordinator> coordinator = open_coordinator(o);
  if (!coordinator) return 1;
  std::unique_ptr<ResponseRecorder> recorder;
  if (!o.record_responses.empty()) {
    std::string error;
    if (!(recorder = ResponseRecorder::open(o.record_responses, error))) {
      std::fprintf(stderr, "tessera-server: --record-responses: %s\n", error.c_str());
      return 2;
    }
  }
  int failure = 0;
  std::unique_ptr<HttpListener> http = HttpListener::open(o, host, port, *coordinator, tokens, recorder.get(), failure);
  if (!http) return failure;
  const int bound = http->port();
  if (!o.port_file.empty()) std::ofstream(o.port_file) << bound << "\n";
  const bool tls = !o.tls_cert.empty();
  const std::string local_host = host == "0.0.0.0" || host == "::" ? std::string("127.0.0.1") : host;
  const std::string url = (tls ? "https://" : "http://") + local_host + ":" + std::to_string(bound);
  log_event(spdlog::level::info, "server.listening",
            {{"version", TESSERA_VERSION}, {"url", url}, {"data_dir", o.coordinator.data_dir},
             {"http_threads", o.http_threads}, {"upload_threads", http->threads() - o.http_threads}, {"tls", tls},
             {"tokens", tokens.enabled()}});
  http->start();

  LocalWorkers workers(o, url, tokens.worker);
  for (;;) {
    timespec tick{1, 0};
    const int sig = sigtimedwait(&signals, nullptr, &tick);
    if (sig == SIGTERM || sig == SIGINT) {
      spdlog::info("tessera-server: signal {}, shutting down", sig);
      break;
    }
    workers.restart_exited();
  }
  // Workers first (they deliver finished passes and sign off over HTTP), then HTTP.
  workers.signal_stop();
  coordinator->shutdown();  // long polls return at once; results and sign-offs are still taken
  workers.wait();
  http->stop();
  return 0;
}

}  // namespace tessera::server
