#include "local_workers.h"

#include "tessera/farm/cache_lock.h"

#include <spdlog/spdlog.h>

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
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

// In the child, between fork and exec: only async-signal-safe calls (argv and envp were built
// before the fork: another thread may have held the allocator's lock).
[[noreturn]] void exec_worker(char* const* argv, char* const* envp, pid_t parent) {
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, nullptr);
  setpgid(0, 0);
  prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (getppid() != parent) _exit(1);  // (the coordinator died before the death signal was armed)
  execve(argv[0], argv, envp);
  static const char msg[] = "tessera-server: cannot run the local worker program (--worker-binary)\n";
  (void)!write(2, msg, sizeof msg - 1);
  _exit(127);
}

std::vector<char*> pointers(std::vector<std::string>& strings) {
  std::vector<char*> out;
  for (std::string& s : strings) out.push_back(s.data());
  out.push_back(nullptr);
  return out;
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
  const std::vector<char*> argv = pointers(args), envp = pointers(env);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid == 0) exec_worker(argv.data(), envp.data(), parent);
  return pid;
}

// A process still holding the slot's cache folder (a worker a dead coordinator started, before
// workers died with it, or one run by hand on that folder) is killed, and its claim waited out.
void evict_holder(const std::string& cache) {
  const pid_t holder = farm::CacheLock::holder(cache);
  if (holder <= 0 || holder == getpid()) return;
  spdlog::warn("local worker cache {} is held by process {}; stopping it (one worker per cache folder)", cache, holder);
  kill(holder, SIGKILL);
  for (int i = 0; i < 100 && farm::CacheLock::holder(cache) == holder; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

}  // namespace

LocalWorkers::LocalWorkers(const ServerOptions& o, std::string url, std::string token)
    : o_(o), binary_(find_worker_binary(o)), url_(std::move(url)), token_(std::move(token)),
      threads_(o.local_worker_threads > 0
                   ? o.local_worker_threads
                   : std::max(1, int(std::thread::hardware_concurrency()) / std::max(1, o.local_workers))),
      pids_(size_t(o.local_workers), 0) {
  for (int i = 0; i < o.local_workers; ++i) pids_[size_t(i)] = spawn(i);
}

std::string LocalWorkers::cache_dir(int slot) const {
  return (fs::path(o_.coordinator.data_dir) / "local-workers" / std::to_string(slot)).string();
}

void LocalWorkers::restart_exited() {
  for (int i = 0; i < o_.local_workers; ++i) {
    int status = 0;
    if (pids_[size_t(i)] > 0 && waitpid(pids_[size_t(i)], &status, WNOHANG) == pids_[size_t(i)]) {
      spdlog::warn("local worker {} exited (status {}); restarting it", i, status);
      pids_[size_t(i)] = spawn(i);
    }
  }
}

void LocalWorkers::signal_stop() {
  for (pid_t pid : pids_)
    if (pid > 0) kill(pid, SIGTERM);
}

void LocalWorkers::wait() {
  for (pid_t pid : pids_)
    if (pid > 0) waitpid(pid, nullptr, 0);
}

pid_t LocalWorkers::spawn(int slot) {
  const std::string cache = cache_dir(slot);
  evict_holder(cache);
  return spawn_worker(binary_, url_, threads_, slot, cache, token_, o_.tls_cert);
}

}  // namespace tessera::server
