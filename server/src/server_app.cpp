#include "tessera/server/server_app.h"

#include "connection_guard.h"
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

}  // namespace

int run_scene_planner_main() { return run_scene_planner(stdin, stdout); }

int run_server(const ServerOptions& o) {
  // Buffers of 1 MiB and more (images being written or served, films) are mapped and given back
  // to the system when freed. Without a fixed threshold glibc raises it after the first large
  // free and serves later ones from per-thread heaps, which keep their peak: the coordinator's
  // resident memory then grows with every image it ever wrote (bench/coordinator_memory.sh).
  // Fixing it also fixes the trim threshold, whose 128 KiB default would hand heap tops back and
  // fault them in again for every tile result (+20% CPU per unit in bench/farm_load.sh).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
  // Signals are taken synchronously by this thread (sigtimedwait), so every other thread,
  // including httplib's, runs with them blocked.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  ::signal(SIGPIPE, SIG_IGN);

  size_t colon = o.listen.rfind(':');
  if (colon == std::string::npos) {
    std::fprintf(stderr, "tessera-server: --listen '%s': expected HOST:PORT\n", o.listen.c_str());
    return 2;
  }
  const std::string host = o.listen.substr(0, colon);
  int port = 0;
  try {
    port = std::stoi(o.listen.substr(colon + 1));
  } catch (const std::exception&) {
    std::fprintf(stderr, "tessera-server: --listen '%s': bad port\n", o.listen.c_str());
    return 2;
  }

  try {
    configure_logging(o.log_format, o.log_level);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera-server: %s\n", e.what());
    return 2;
  }
  AuthTokens tokens;
  try {
    tokens.client = resolve_token(o.client_token, o.client_token_file, "TESSERA_CLIENT_TOKEN");
    tokens.worker = resolve_token(o.worker_token, o.worker_token_file, "TESSERA_WORKER_TOKEN");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera-server: %s\n", e.what());
    return 2;
  }
  if (!tokens.enabled() && host != "127.0.0.1" && host != "localhost" && host != "::1")
    spdlog::warn("no client or worker token: anyone who can reach {} can use this farm", o.listen);

  std::unique_ptr<Coordinator> coordinator;
  try {
    CoordinatorOptions copt = o.coordinator;
    // This very program plans scenes in a child (`--plan-scene`): the coordinator's memory stays
    // that of its bookkeeping, however large the scenes submitted.
    std::error_code ec;
    if (copt.scene_planner.empty()) copt.scene_planner = fs::read_symlink("/proc/self/exe", ec).string();
    coordinator = std::make_unique<Coordinator>(copt);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "tessera-server: cannot use data directory '%s': %s\n", o.coordinator.data_dir.c_str(), e.what());
    return 1;
  }

  const bool tls = !o.tls_cert.empty();
  std::unique_ptr<httplib::Server> http_ptr;
  if (tls) {
    auto ssl = std::make_unique<httplib::SSLServer>(o.tls_cert.c_str(), o.tls_key.c_str());
    if (!ssl->is_valid()) {
      std::fprintf(stderr, "tessera-server: cannot use --tls-cert '%s' with --tls-key '%s' (not PEM, or the key does not match)\n",
                   o.tls_cert.c_str(), o.tls_key.c_str());
      return 2;
    }
    http_ptr = std::move(ssl);
  } else {
    http_ptr = std::make_unique<httplib::Server>();
  }
  httplib::Server& http = *http_ptr;
  const int threads = o.http_threads;
  http.new_task_queue = [threads] { return new httplib::ThreadPool(size_t(threads)); };
  // A kept-alive idle connection holds an HTTP thread; keep that short so idle clients and
  // workers cannot pin the pool.
  http.set_keep_alive_timeout(2);
  http.set_read_timeout(60);
  // cpp-httplib 0.11 listens with a backlog of 5; a few hundred workers connecting at once would
  // overflow it (dropped handshakes, failed requests). Keep the socket and widen the backlog after
  // bind: listen() on a listening socket only changes its backlog.
  int listen_fd = -1;
  http.set_socket_options([&listen_fd](int fd) {
    httplib::default_socket_options(fd);
    listen_fd = fd;
  });
  int bound = port == 0 ? http.bind_to_any_port(host) : (http.bind_to_port(host, port) ? port : -1);
  if (bound <= 0) {
    std::fprintf(stderr, "tessera-server: cannot listen on %s\n", o.listen.c_str());
    return 1;
  }
  if (listen_fd >= 0) ::listen(listen_fd, 4096);
  ConnectionGuard guard(bound, o.header_timeout);
  install_routes(http, *coordinator, o.coordinator.max_upload_bytes, tokens, &guard);
  if (!o.port_file.empty()) std::ofstream(o.port_file) << bound << "\n";
  const std::string local_host = host == "0.0.0.0" || host == "::" ? std::string("127.0.0.1") : host;
  const std::string url = (tls ? "https://" : "http://") + local_host + ":" + std::to_string(bound);
  log_event(spdlog::level::info, "server.listening",
            {{"version", TESSERA_VERSION}, {"url", url}, {"data_dir", o.coordinator.data_dir}, {"http_threads", threads},
             {"tls", tls}, {"tokens", tokens.enabled()}});
  std::thread listener([&http] { http.listen_after_bind(); });

  // Local workers: restarted if they die, stopped with the server.
  const std::string binary = find_worker_binary(o);
  const int per_worker = o.local_worker_threads > 0
                             ? o.local_worker_threads
                             : std::max(1, int(std::thread::hardware_concurrency()) / std::max(1, o.local_workers));
  std::vector<pid_t> children(size_t(o.local_workers), 0);
  auto cache = [&](int i) {
    return (fs::path(o.coordinator.data_dir) / "local-workers" / std::to_string(i)).string();
  };
  for (int i = 0; i < o.local_workers; ++i) children[size_t(i)] = spawn_worker(binary, url, per_worker, i, cache(i), tokens.worker, o.tls_cert);

  int exit_code = 0;
  for (;;) {
    timespec tick{1, 0};
    int sig = sigtimedwait(&signals, nullptr, &tick);
    if (sig == SIGTERM || sig == SIGINT) {
      spdlog::info("tessera-server: signal {}, shutting down", sig);
      break;
    }
    for (int i = 0; i < o.local_workers; ++i) {
      int status = 0;
      if (children[size_t(i)] > 0 && waitpid(children[size_t(i)], &status, WNOHANG) == children[size_t(i)]) {
        spdlog::warn("local worker {} exited (status {}); restarting it", i, status);
        children[size_t(i)] = spawn_worker(binary, url, per_worker, i, cache(i), tokens.worker, o.tls_cert);
      }
    }
  }
  // Workers first (they deliver finished passes and sign off over HTTP), then HTTP.
  for (pid_t pid : children)
    if (pid > 0) kill(pid, SIGTERM);
  coordinator->shutdown();  // long polls return at once; results and sign-offs are still taken
  for (pid_t pid : children)
    if (pid > 0) waitpid(pid, nullptr, 0);
  http.stop();
  listener.join();
  return exit_code;
}

}  // namespace tessera::server
