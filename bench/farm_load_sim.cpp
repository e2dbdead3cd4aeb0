// The coordinator process, CPU accounting and the simulated workers of tessera-farm-load.
#include "farm_load.h"

#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/protocol.h"
#include "tessera/farm/tile_result.h"
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

namespace {

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void sleep_unless_stopped(const SimShared& shared, double seconds) {
  for (auto end = Clock::now() + std::chrono::duration<double>(seconds); Clock::now() < end && !shared.stop;)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
}

}  // namespace

ServerProcess::ServerProcess(const std::string& binary, const std::string& dir, int http_threads,
                             double max_poll_wait) {
  const std::string port_file = (fs::path(dir) / "port").string();
  log_ = (fs::path(dir) / "server.log").string();
  std::vector<std::string> args = {binary, "--listen", "127.0.0.1:0", "--port-file", port_file,
                                   "--data-dir", (fs::path(dir) / "data").string(),
                                   "--http-threads", std::to_string(http_threads),
                                   "--max-poll-wait", std::to_string(max_poll_wait),
                                   // Each unit leased once: the run checks every lease ends accepted.
                                   "--no-speculation"};
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

namespace {

// Pixel sums with the size and entropy of a real pass (so the bytes on the wire and in the store
// are realistic), for exactly the leased unit.
void fill_synthetic(const Lease& lease, uint64_t& rng, TileResult& result) {
  result.job_id = lease.job_id;
  result.tile = lease.tile;
  result.pass = lease.pass;
  result.sample_begin = lease.sample_begin;
  result.sample_end = lease.sample_end;
  result.seconds = 0.001;
  result.film.reset(lease.rect);
  const uint32_t n = lease.sample_end - lease.sample_begin;
  for (PixelSums& p : result.film.mutable_pixels()) {
    for (int c = 0; c < 3; ++c) {
      rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;  // xorshift64
      const double v = double(rng >> 11) * 0x1p-53;
      p.sum[c] = v * n;
      p.sum_sq[c] = v * v * n;
    }
    p.count = n;
  }
  result.film.counters.samples = uint64_t(lease.rect.area()) * n;
  result.film.counters.camera_rays = result.film.counters.samples;
}

void note_error(SimStats& st, const std::string& what) {
  if (st.errors++ == 0) st.first_error = what;
}

// Uploads one result, retrying transport failures and 5xx a few times (the real worker retries
// for minutes; here a lost upload is a finding).
void upload(const client::FarmApi& api, uint64_t worker, const Lease& lease, const std::string& bytes,
            SimShared& shared, SimStats& st) {
  for (int attempt = 0; attempt < 3; ++attempt) {
    const auto t0 = Clock::now();
    client::ApiReply<client::ResultAck> r = api.upload_result(worker, lease.id, bytes);
    if (r.ok()) {
      st.upload_ms.push_back(ms_since(t0));
      if (r.value.duplicate) {
        ++st.duplicates;
      } else if (r.value.accepted) {
        ++st.accepted;
        ++shared.accepted;
      } else {
        note_error(st, "upload answered neither accepted nor duplicate: " + r.http.body);
      }
      return;
    }
    if (r.http.status != 0 && r.http.status < 500) {
      note_error(st, "upload of job " + std::to_string(lease.job_id) + " unit " + std::to_string(lease.tile) + "/" +
                         std::to_string(lease.pass) + " refused: " + r.describe());
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  note_error(st, "upload failed three times");
}

}  // namespace

void run_simulated_worker(int index, SimShared& shared, SimStats& st) {
  try {
    client::FarmApi api(client::FarmClient(shared.url));
    const BuildFingerprint& fp = build_fingerprint();  // the check the real worker passes
    WorkerHello hello{"load-" + std::to_string(index), 1, uint64_t(1) << 30, fp.version, fp.isa, fp.probe};
    client::ApiReply<client::Registration> reg = api.register_worker(hello);
    const uint64_t id = reg.ok() ? reg.value.id : 0;
    st.registered = id != 0;
    ++shared.registered;
    if (!st.registered) return note_error(st, "registration: " + reg.describe());
    while (!shared.start && !shared.stop) std::this_thread::sleep_for(std::chrono::milliseconds(1));

    uint64_t rng = 0x9E3779B97F4A7C15ull * uint64_t(index + 1);
    TileResult result;
    while (!shared.stop) {
      const auto t0 = Clock::now();
      client::ApiReply<std::optional<Lease>> r = api.lease(id, shared.poll_wait, shared.poll_wait + 15);
      const double ms = ms_since(t0);
      if (r.ok() && !r.value) {
        ++st.empty_polls;
        // Answered at once: the coordinator's long-poll slots are full; back off as tessera-worker does.
        if (ms < 500) sleep_unless_stopped(shared, 0.25);
        continue;
      }
      if (!r.ok()) {
        note_error(st, "lease request: " + r.describe());
        sleep_unless_stopped(shared, 0.1);
        continue;
      }
      const Lease& lease = *r.value;
      st.lease_ms.push_back(ms);
      ++st.leased;
      // A lease taken is completed even when stopping: every unit leased must end accepted.
      fill_synthetic(lease, rng, result);
      upload(api, id, lease, encode_tile_result(result), shared, st);
    }
    client::HttpReply off = api.sign_off(id);
    st.signed_off = off.ok();
    if (!off.ok()) note_error(st, "sign-off: " + off.describe());
  } catch (const std::exception& e) {
    note_error(st, std::string("exception: ") + e.what());
  }
}

}  // namespace tessera::bench
