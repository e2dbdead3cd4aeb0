#include "tessera/server/server_app.h"

#include "connection_guard.h"
#include "response_recorder.h"
#include "event_log.h"
#include "scene_planner.h"
#include "tessera/farm/protocol.h"
#include "tessera/server/http_api.h"

#include <httplib.h>
#include <spdlog/spdlog.h>

#include <malloc.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>

namespace tessera::server {

namespace fs = std::filesystem;

namespace {

std::string find_worker_binary(const ServerOptions& o) {
  if (!o.worker_binary.empty()) return o.worker_binary;
  std::error_code ec;
  fs::path self = fs::read_symlink("/proc/self/exe", ec).parent_path();
  for (fs::path p : {self / "tessera-worker", self / ".." / "worker" / "tessera-worker"})
    if (fs::exists(p, ec)) return p.lexically_normal().string();
  return "tessera-worker";
}

pid_t spawn_worker(const std::string& binary, const std::string& url, int threads, int index,
                   const std::string& cache, const std::string& token, const std::string& ca_file) {
  // The worker token travels in the environment (never on a command line that `ps` shows).
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e)
    if (std::string(*e).rfind("TESSERA_WORKER_TOKEN=", 0) != 0) env.emplace_back(*e);
  if (!token.empty()) env.push_back("TESSERA_WORKER_TOKEN=" + token);
  std::vector<std::string> args = {binary, "--server", url, "--threads", std::to_string(threads),
                                   "--name", "local-" + std::to_string(index), "--cache-dir", cache};
  // Over https the local workers trust the server's own certificate (it must name --listen's host).
  if (!ca_file.empty()) args.insert(args.end(), {"--ca-file", ca_file});
  pid_t pid = fork();
  if (pid == 0) {
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<char*> envp;
    for (auto& e : env) envp.push_back(e.data());
    envp.push_back(nullptr);
    execve(binary.c_str(), argv.data(), envp.data());
    std::fprintf(stderr, "tessera-server: cannot run %s: %s\n", binary.c_str(), std::strerror(errno));
    _exit(127);
  }
  return pid;
}

// Local workers (--local-workers): restarted if they die, stopped with the server.
class LocalWorkers {
 public:
  LocalWorkers(const ServerOptions& o, std::string url, std::string token)
      : o_(o), binary_(find_worker_binary(o)), url_(std::move(url)), token_(std::move(token)),
        threads_(o.local_worker_threads > 0
                     ? o.local_worker_threads
                     : std::max(1, int(std::thread::hardware_concurrency()) / std::max(1, o.local_workers))),
        pids_(size_t(o.local_workers), 0) {
    for (int i = 0; i < o.local_workers; ++i) pids_[size_t(i)] = spawn(i);
  }
  void restart_exited() {
    for (int i = 0; i < o_.local_workers; ++i) {
      int status = 0;
      if (pids_[size_t(i)] > 0 && waitpid(pids_[size_t(i)], &status, WNOHANG) == pids_[size_t(i)]) {
        spdlog::warn("local worker {} exited (status {}); restarting it", i, status);
        pids_[size_t(i)] = spawn(i);
      }
    }
  }
  void signal_stop() {
    for (pid_t pid : pids_)
      if (pid > 0) kill(pid, SIGTERM);
  }
  void wait() {
    for (pid_t pid : pids_)
      if (pid > 0) waitpid(pid, nullptr, 0);
  }

 private:
  pid_t spawn(int i) {
    const std::string cache = (fs::path(o_.coordinator.data_dir) / "local-workers" / std::to_string(i)).string();
    return spawn_worker(binary_, url_, threads_, i, cache, token_, o_.tls_cert);
  }
  const ServerOptions& o_;
  const std::string binary_, url_, token_;
  const int threads_;
  std::vector<pid_t> pids_;
};

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

// The HTTP(S) server with its pool and timeouts; null (with a message) for an unusable certificate.
std::unique_ptr<httplib::Server> make_http_server(const ServerOptions& o) {
  std::unique_ptr<httplib::Server> http;
  if (!o.tls_cert.empty()) {
    auto ssl = std::make_unique<httplib::SSLServer>(o.tls_cert.c_str(), o.tls_key.c_str());
    if (!ssl->is_valid()) {
      std::fprintf(stderr, "tessera-server: cannot use --tls-cert '%s' with --tls-key '%s' (not PEM, or the key does not match)\n",
                   o.tls_cert.c_str(), o.tls_key.c_str());
      return nullptr;
    }
    http = std::move(ssl);
  } else {
    http = std::make_unique<httplib::Server>();
  }
  const int threads = o.http_threads;
  http->new_task_queue = [threads] { return new httplib::ThreadPool(size_t(threads)); };
  // A kept-alive idle connection holds an HTTP thread; keep that short so idle clients and
  // workers cannot pin the pool.
  http->set_keep_alive_timeout(2);
  http->set_read_timeout(60);
  return http;
}

// Binds HOST:PORT (0: any free port); the port bound, or -1.
int bind_http(httplib::Server& http, const std::string& host, int port) {
  // cpp-httplib 0.11 listens with a backlog of 5; a few hundred workers connecting at once would
  // overflow it (dropped handshakes, failed requests). Keep the socket and widen the backlog after
  // bind: listen() on a listening socket only changes its backlog.
  int listen_fd = -1;
  http.set_socket_options([&listen_fd](int fd) {
    httplib::default_socket_options(fd);
    listen_fd = fd;
  });
  const int bound = port == 0 ? http.bind_to_any_port(host) : (http.bind_to_port(host, port) ? port : -1);
  if (bound > 0 && listen_fd >= 0) ::listen(listen_fd, 4096);
  return bound > 0 ? bound : -1;
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
  std::unique_ptr<httplib::Server> http = make_http_server(o);
  if (!http) return 2;
  const int bound = bind_http(*http, host, port);
  if (bound <= 0) {
    std::fprintf(stderr, "tessera-server: cannot listen on %s\n", o.listen.c_str());
    return 1;
  }
  std::unique_ptr<ResponseRecorder> recorder;
  if (!o.record_responses.empty()) {
    std::string error;
    if (!(recorder = ResponseRecorder::open(o.record_responses, error))) {
      std::fprintf(stderr, "tessera-server: --record-responses: %s\n", error.c_str());
      return 2;
    }
  }
  ConnectionGuard guard(bound, o.header_timeout);
  (void)install_routes(*http, *coordinator, o.coordinator.max_upload_bytes, tokens, &guard, recorder.get());
  if (!o.port_file.empty()) std::ofstream(o.port_file) << bound << "\n";
  const bool tls = !o.tls_cert.empty();
  const std::string local_host = host == "0.0.0.0" || host == "::" ? std::string("127.0.0.1") : host;
  const std::string url = (tls ? "https://" : "http://") + local_host + ":" + std::to_string(bound);
  log_event(spdlog::level::info, "server.listening",
            {{"version", TESSERA_VERSION}, {"url", url}, {"data_dir", o.coordinator.data_dir},
             {"http_threads", o.http_threads}, {"tls", tls}, {"tokens", tokens.enabled()}});
  std::thread listener([&http] { http->listen_after_bind(); });

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
  listener.join();
  return 0;
}

}  // namespace tessera::server
