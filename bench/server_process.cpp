// The coordinator process and CPU accounting of tessera-farm-load.
#include "farm_load.h"

#include "tessera/client/farm_api.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace tessera::bench {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using nlohmann::json;


ServerProcess::ServerProcess(const std::string& binary, const std::string& dir, int http_threads,
                             double max_poll_wait, const std::vector<std::string>& extra_args) {
  const std::string port_file = (fs::path(dir) / "port").string();
  log_ = (fs::path(dir) / "server.log").string();
  std::vector<std::string> args = {binary, "--listen", "127.0.0.1:0", "--port-file", port_file,
                                   "--data-dir", (fs::path(dir) / "data").string(),
                                   "--http-threads", std::to_string(http_threads),
                                   "--max-poll-wait", std::to_string(max_poll_wait),
                                   // Each unit leased once: the run checks every lease ends accepted.
                                   "--no-speculation"};
  args.insert(args.end(), extra_args.begin(), extra_args.end());
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e) {
    std::string entry(*e);
    if (entry.rfind("TESSERA_CLIENT_TOKEN=", 0) != 0 && entry.rfind("TESSERA_WORKER_TOKEN=", 0) != 0)
      env.push_back(entry);
  }
  // Everything the child touches is prepared here: after fork() only async-signal-safe calls.
  std::vector<char*> argv, envp;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  const pid_t parent = getpid();
  pid_ = fork();
  if (pid_ < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid_ == 0) {
    prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlives the benchmark, even after kill -9
    if (getppid() != parent) _exit(1);
    int fd = open(log_.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (fd >= 0) {
      dup2(fd, 1);
      dup2(fd, 2);
    }
    execve(argv[0], argv.data(), envp.data());
    _exit(127);
  }
  int port = 0;
  for (auto end = Clock::now() + std::chrono::seconds(20); port == 0 && Clock::now() < end && alive();) {
    std::ifstream in(port_file);
    if (!(in >> port)) port = 0;
    if (port == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  url_ = "http://127.0.0.1:" + std::to_string(port);
  bool healthy = false;
  for (auto end = Clock::now() + std::chrono::seconds(20); port > 0 && !healthy && Clock::now() < end && alive();) {
    healthy = client::FarmApi(client::FarmClient(url_)).health(2).status == 200;
    if (!healthy) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!healthy) {
    stop(2);
    throw std::runtime_error("tessera-server (" + binary + ") did not start; its log:\n" + log_tail(20));
  }
}

bool ServerProcess::alive() {
  if (pid_ <= 0) return false;
  int status = 0;
  if (waitpid(pid_, &status, WNOHANG) != pid_) return true;
  exit_status_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  pid_ = -1;
  return false;
}

int ServerProcess::stop(double seconds) {
  if (pid_ <= 0) return exit_status_;
  ::kill(pid_, SIGTERM);
  for (auto end = Clock::now() + std::chrono::duration<double>(seconds); Clock::now() < end;) {
    if (!alive()) return exit_status_;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid_, SIGKILL);
  waitpid(pid_, nullptr, 0);
  pid_ = -1;
  exit_status_ = -1;
  return -1;
}

std::string ServerProcess::log_tail(int lines) const {
  std::ifstream in(log_);
  std::deque<std::string> last;
  for (std::string line; std::getline(in, line);) {
    last.push_back(line);
    if (int(last.size()) > lines) last.pop_front();
  }
  std::string out;
  for (auto& l : last) out += "  " + l + "\n";
  return out;
}

double process_cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Fields after "(comm)", which may itself hold spaces: state is field 3, utime 14, stime 15.
  const size_t paren = stat.rfind(')');
  if (paren == std::string::npos) return -1;
  std::istringstream fields(stat.substr(paren + 1));
  std::string field;
  unsigned long long utime = 0, stime = 0;
  for (int i = 3; i <= 15 && fields >> field; ++i) {
    if (i == 14) utime = std::stoull(field);
    if (i == 15) stime = std::stoull(field);
  }
  if (!fields) return -1;
  return double(utime + stime) / double(sysconf(_SC_CLK_TCK));
}

double self_cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  auto seconds = [](const timeval& t) { return double(t.tv_sec) + 1e-6 * double(t.tv_usec); };
  return seconds(u.ru_utime) + seconds(u.ru_stime);
}

}  // namespace tessera::bench
