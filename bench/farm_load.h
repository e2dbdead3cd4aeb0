// tessera-farm-load: a load benchmark of one coordinator. The pieces of the driver (farm_load.cpp):
// the coordinator as a child process and CPU time of a process (server_process.cpp), and the
// simulated workers (sim_workers.cpp: real protocol, the client library's requests, synthetic tile
// results, no rendering; many workers per thread on an event loop).
#pragma once

#include <sys/types.h>

#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace tessera::bench {

/// tessera-server on 127.0.0.1 port 0 with its own --data-dir under `dir`; farm tokens are
/// removed from its environment (the farm is open, as on loopback by default). It dies with this
/// process (PR_SET_PDEATHSIG) and is stopped (SIGTERM, then SIGKILL) when destroyed.
class ServerProcess {
 public:
  ServerProcess(const std::string& binary, const std::string& dir, int http_threads, double max_poll_wait,
                const std::vector<std::string>& extra_args = {});
  ~ServerProcess() { stop(); }
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  pid_t pid() const { return pid_; }
  const std::string& url() const { return url_; }
  /// False once the process has exited (reaped here).
  bool alive();
  /// SIGTERM, up to `seconds` to exit, then SIGKILL. The exit status, or -1 if it had to be killed.
  int stop(double seconds = 10);
  /// The last `lines` lines of its log, for failure messages.
  std::string log_tail(int lines) const;

 private:
  pid_t pid_ = -1;
  int exit_status_ = -1;
  std::string url_, log_;
};

/// utime + stime of `pid` (from /proc/<pid>/stat), seconds; negative if unreadable.
double process_cpu_seconds(pid_t pid);
/// This process's user + system CPU, seconds.
double self_cpu_seconds();

/// What every simulated worker reads; the driver flips `start` and `stop`.
struct SimShared {
  std::string url;
  double poll_wait = 2;          // seconds per lease long poll (?wait=)
  std::atomic<bool> start{false}, stop{false};
  std::atomic<int> registered{0};        // workers that tried to register (successfully or not)
  std::atomic<uint64_t> accepted{0};     // results accepted, over all workers
};

/// One simulated worker's account of its run.
struct SimStats {
  bool registered = false, signed_off = false;
  uint64_t leased = 0, accepted = 0, duplicates = 0, empty_polls = 0, errors = 0;
  std::vector<double> lease_ms, upload_ms;  // latency of each granted lease / each upload
  std::string first_error;
};

/// Registers workers first..first+count-1 (their stats at those indices), then (once `start`)
/// drives them all from this thread: each leases and completes units as fast as the coordinator
/// allows until `stop`, then signs off. Never throws; problems are counted in the stats' errors.
void run_simulated_workers(int first, int count, SimShared& shared, std::vector<SimStats>& stats);

}  // namespace tessera::bench
