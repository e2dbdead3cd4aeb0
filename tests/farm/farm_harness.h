// Runs a real farm for integration tests: tessera-server and tessera-worker as child processes on
// loopback, ports chosen free at run time (port 0 + --port-file), a client for the API.
#pragma once

#include "tessera/farm/bundle.h"
#include "tessera/farm/job_scene.h"
#include "tessera/image/image.h"
#include "tessera/sequence/renderer.h"
#include "tessera/client/farm_api.h"
#include "test_support.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace tessera::test {

/// A child process; killed (SIGKILL) and reaped when destroyed.
class Child {
 public:
  Child() = default;
  /// `env`: NAME=value entries added to (or replacing) this process's environment.
  Child(const std::vector<std::string>& args, const std::string& log, const std::vector<std::string>& env = {}) {
    std::vector<std::string> environment;
    for (char** e = environ; *e; ++e) {
      std::string entry(*e);
      bool replaced = false;
      for (const auto& x : env) replaced |= entry.substr(0, entry.find('=') + 1) == x.substr(0, x.find('=') + 1);
      if (!replaced) environment.push_back(entry);
    }
    environment.insert(environment.end(), env.begin(), env.end());
    pid_ = fork();
    if (pid_ == 0) {
      FILE* f = std::fopen(log.c_str(), "a");
      if (f) {
        dup2(fileno(f), 1);
        dup2(fileno(f), 2);
      }
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      std::vector<char*> envp;
      for (auto& e : environment) envp.push_back(const_cast<char*>(e.c_str()));
      envp.push_back(nullptr);
      execve(argv[0], argv.data(), envp.data());
      _exit(127);
    }
  }
  Child(Child&& o) noexcept : pid_(o.pid_) { o.pid_ = -1; }
  Child& operator=(Child&& o) noexcept {
    std::swap(pid_, o.pid_);
    return *this;
  }
  ~Child() { kill_now(); }
  pid_t pid() const { return pid_; }
  void kill_now() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
      pid_ = -1;
    }
  }
  /// Waits up to `seconds` for the process to exit by itself; its exit status, or -1.
  int wait_exit(double seconds) {
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (pid_ > 0 && std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }
  /// SIGTERM and wait; returns the exit status (or -1 after `seconds`, then SIGKILL).
  int terminate(double seconds = 20) {
    if (pid_ <= 0) return -1;
    ::kill(pid_, SIGTERM);
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      int status = 0;
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    kill_now();
    return -1;
  }

 private:
  pid_t pid_ = -1;
};

class Farm {
 public:
  explicit Farm(std::vector<std::string> server_flags = {}) : flags_(std::move(server_flags)) {}

  /// Starts (or restarts on the same port and data dir) the coordinator; waits for /healthz.
  void start_server() {
    const std::string port_file = (dir_.path / "port").string();
    std::filesystem::remove(port_file);
    std::vector<std::string> args = {TESSERA_SERVER_BIN, "--listen", "127.0.0.1:" + std::to_string(port_),
                                     "--port-file", port_file, "--data-dir", (dir_.path / "data").string()};
    args.insert(args.end(), flags_.begin(), flags_.end());
    // With TESSERA_RECORD_RESPONSES=DIR, every answer goes to a file of its own in DIR, for
    // tests/docs/openapi_responses_test.py (tests/CMakeLists.txt sets it).
    if (const char* dir = std::getenv("TESSERA_RECORD_RESPONSES"); dir && *dir) {
      static std::atomic<int> servers{0};
      args.insert(args.end(), {"--record-responses", std::string(dir) + "/responses-" + std::to_string(::getpid()) +
                                                         "-" + std::to_string(servers++) + ".jsonl"});
    }
    server_ = Child(args, log("server"));
    for (int i = 0; i < 500 && port_ == 0; ++i) {
      std::ifstream in(port_file);
      if (!(in >> port_)) port_ = 0;
      if (port_ == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ASSERT_GT(port_, 0) << "the server did not start; log: " << log("server");
    for (int i = 0; i < 500; ++i) {
      if (client().get("/healthz", 2).ok()) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::ifstream log_file(log("server"));
    const std::string text((std::istreambuf_iterator<char>(log_file)), std::istreambuf_iterator<char>());
    FAIL() << "the server does not answer /healthz; its log ends with:\n" << text.substr(text.size() > 3000 ? text.size() - 3000 : 0);
  }
  void kill_server() { server_.kill_now(); }
  /// The coordinator's --data-dir.
  std::filesystem::path data_dir() const { return dir_.path / "data"; }
  pid_t server_pid() const { return server_.pid(); }
  int stop_server() { return server_.terminate(); }
  /// Serve https with this certificate and key; the harness's client and workers verify against
  /// `ca_file` (the certificate itself, when self-signed).
  void use_tls(const std::string& cert, const std::string& key, const std::string& ca_file) {
    flags_.insert(flags_.end(), {"--tls-cert", cert, "--tls-key", key});
    ca_file_ = ca_file;
  }
  /// Tokens the harness's client and workers use (the server's flags set the real ones).
  void set_tokens(std::string client, std::string worker) {
    client_token_ = std::move(client);
    worker_token_ = std::move(worker);
  }
  Child& add_worker(int threads = 1, std::vector<std::string> extra = {}) {
    const std::string n = std::to_string(workers_.size());
    std::vector<std::string> args = {TESSERA_WORKER_BIN, "--server", url(), "--threads", std::to_string(threads),
                                     "--name", "w" + n, "--cache-dir", (dir_.path / ("cache" + n)).string(),
                                     "--poll-wait", "2"};
    if (!ca_file_.empty()) args.insert(args.end(), {"--ca-file", ca_file_});
    args.insert(args.end(), extra.begin(), extra.end());
    std::vector<std::string> env;
    if (!worker_token_.empty()) env.push_back("TESSERA_WORKER_TOKEN=" + worker_token_);
    workers_.emplace_back(args, log("worker" + n), env);
    return workers_.back();
  }
  Child& worker(size_t i) { return workers_[i]; }
  /// Waits until `n` workers are registered and idle/busy.
  bool wait_workers(size_t n, double seconds = 20) {
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      nlohmann::json j = client().get("/api/v1/workers").json();
      size_t live = 0;
      if (j.is_object())
        for (auto& w : j["workers"]) live += w["state"] == "idle" || w["state"] == "busy";
      if (live >= n) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }

  std::string url() const { return (ca_file_.empty() ? "http://" : "https://") + std::string("127.0.0.1:") + std::to_string(port_); }
  int port() const { return port_; }
  const std::string& ca_file() const { return ca_file_; }
  client::FarmClient client() const { return client::FarmClient(url(), client_token_, ca_file_); }
  client::FarmApi api() const { return client::FarmApi(client()); }
  const TempDir& dir() const { return dir_; }
  std::string log(const std::string& name) const { return (dir_.path / (name + ".log")).string(); }

  /// Submits `scene` (bundled as `tessera submit` does) with `settings`; returns the job id (0 on error).
  uint64_t submit(const std::string& scene, JobSettings settings, client::HttpReply* reply = nullptr) const {
    auto abs = std::filesystem::absolute(scene);
    LoadedJobScene loaded = load_job_scene(abs.parent_path().string(), abs.filename().string(), settings, /*confine=*/false);
    BundlePlan plan = plan_bundle(abs.string(), scene_files(loaded.desc, loaded.loaded));
    settings.scene_file = plan.files.front();
    nlohmann::json body = to_json(settings);
    body.erase("scene");
    client::HttpReply r = api().submit_job(body, pack_bundle(plan.root_dir, plan.files));
    if (reply) *reply = r;
    return r.status == 201 ? r.json().value("id", uint64_t(0)) : 0;
  }
  nlohmann::json status(uint64_t id) const { return client().get("/api/v1/jobs/" + std::to_string(id)).json(); }
  /// Polls until the job is done/failed/cancelled or `pred(status)` holds; returns the last status.
  template <class Pred>
  nlohmann::json wait_until(uint64_t id, Pred pred, double seconds = 120) const {
    nlohmann::json j;
    auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      j = status(id);
      if (j.is_object()) {
        std::string s = j.value("state", "");
        if (s == "done" || s == "failed" || s == "cancelled" || pred(j)) return j;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(25));
    }
    return j;
  }
  nlohmann::json wait_job(uint64_t id, double seconds = 120) const {
    return wait_until(id, [](const nlohmann::json&) { return false; }, seconds);
  }
  Image image(uint64_t id, ImageAttributes* attributes = nullptr) const {
    client::HttpReply r = client().get("/api/v1/jobs/" + std::to_string(id) + "/image?format=exr", 60);
    std::string path = (dir_.path / ("job" + std::to_string(id) + ".exr")).string();
    std::ofstream(path, std::ios::binary) << r.body;
    return read_exr(path, attributes);
  }

 private:
  TempDir dir_;
  std::vector<std::string> flags_;
  std::string client_token_, worker_token_, ca_file_;
  int port_ = 0;
  Child server_;
  std::vector<Child> workers_;
};

/// The Cornell box of ../shared/scenes, the farm tests' scene.
inline std::string cornell() { return shared_path("scenes/cornell-box/scene.xml"); }

/// `tessera render`'s image for the same scene and settings, rendered in this process.
inline Image local_render(const std::string& scene, const JobSettings& settings) {
  auto abs = std::filesystem::absolute(scene);
  LoadedJobScene loaded = load_job_scene(abs.parent_path().string(), abs.filename().string(), settings, /*confine=*/false);
  RenderSettings rs;
  rs.spp = loaded.loaded.scene->sampler.sample_count;
  rs.seed = settings.seed;
  rs.tile_size = 32;  // deliberately not the farm's tile size
  rs.target_error = settings.target_error;
  rs.adaptive = settings.adaptive;
  rs.guiding = settings.guiding;  // (unset: as the scene's integrator says, as the coordinator decides)
  return render(*loaded.loaded.scene, rs).to_image();
}

/// Number of pixels whose channels differ in any bit (sizes must match).
inline int64_t differing_pixels(const Image& a, const Image& b) {
  if (a.width() != b.width() || a.height() != b.height() || a.channels() != b.channels()) return -1;
  int64_t n = 0;
  const size_t c = size_t(a.channels());
  for (size_t i = 0; i < a.values().size(); i += c)
    n += std::memcmp(&a.values()[i], &b.values()[i], sizeof(float) * c) != 0;
  return n;
}

}  // namespace tessera::test
