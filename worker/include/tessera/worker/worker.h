// tessera-worker: registers with a coordinator, leases tile passes, renders them and uploads the
// sums. One lease loop per thread (each renders one tile pass at a time), one heartbeat thread.
// Rides out coordinator restarts (retries with backoff, registers again when forgotten) and on
// stop finishes the passes it is rendering, hands back the rest and signs off.
#pragma once

#include "tessera/client/farm_api.h"
#include "tessera/farm/cache_lock.h"
#include "tessera/worker/scene_cache.h"

#include <atomic>
#include <cstdint>
#include <map>
#include <optional>
#include <mutex>
#include <string>

namespace tessera::farm {

struct WorkerOptions {
  std::string server;          // http://HOST:PORT
  std::string token;           // the worker bearer token (empty: the farm is open)
  std::string ca_file;         // PEM certificate(s) to verify an https:// coordinator with
  int threads = 0;             // 0: every core
  std::string cache_dir;       // default: $XDG_CACHE_HOME/tessera-worker or ~/.cache/...
  std::string name;            // default: hostname
  uint64_t memory_budget = 0;  // bytes of loaded scenes kept; 0: half the machine's memory
  double poll_wait = 10;       // seconds per lease long poll
  int max_leases = 0;          // stop after this many (tests, benchmarks); 0: no limit
};

struct WorkerStats {
  std::atomic<uint64_t> passes_rendered{0}, passes_uploaded{0}, duplicates{0}, failures{0};
};

class Worker {
 public:
  explicit Worker(WorkerOptions options);
  /// Runs until request_stop() (or max_leases); returns the process exit code: 0, or 3 when the
  /// coordinator refuses this build.
  int run();
  /// Safe from any thread (the signal thread calls it).
  void request_stop() { stop_ = true; }
  const WorkerStats& stats() const { return stats_; }

 private:
  bool register_with_server();
  void slot_loop(int slot);
  void heartbeat_loop();
  /// Renders and delivers one lease; the next lease when the coordinator sent one with the answer.
  std::optional<Lease> process(const Lease& lease);
  /// Delivers a result (asking for the next lease with it while this slot wants more work); its
  /// answer, or nothing when it could not be delivered.
  std::optional<client::ResultAck> upload(const Lease& lease, const std::string& bytes);
  /// The lease's unit rendered and encoded, with the artifact it renders with (if any).
  static std::string render(const Scene& scene, const Lease& lease, const CachedScene* artifact);
  bool wants_more() const { return !stop_ && (opt_.max_leases <= 0 || leases_taken_ < opt_.max_leases); }
  void backoff(int& attempt, bool interruptible = true);

  WorkerOptions opt_;
  client::FarmApi api_;
  CacheLock cache_lock_;  // (before the cache: one worker per cache folder)
  SceneCache cache_;
  std::atomic<bool> stop_{false}, refused_{false};
  std::atomic<uint64_t> worker_id_{0};
  std::atomic<double> heartbeat_seconds_{5};
  std::mutex register_mutex_;
  std::mutex leases_mutex_;
  std::map<uint64_t, Lease> active_;   // leases being rendered (for heartbeats)
  std::map<uint64_t, bool> dropped_;   // the coordinator no longer wants these
  std::atomic<int> leases_taken_{0};
  WorkerStats stats_;
};

/// Defaults filled in (threads, cache dir, name, memory budget).
WorkerOptions resolve_worker_options(WorkerOptions o);

}  // namespace tessera::farm
