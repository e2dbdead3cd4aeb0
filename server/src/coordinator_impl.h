// The coordinator's shared state (one mutex guards all of it; SQLite writes happen under it,
// which serialises them as SQLite would anyway).
#pragma once

#include "job_state.h"
#include "metrics.h"
#include "retention.h"
#include "webhooks.h"
#include "tessera/farm/build_fingerprint.h"
#include "tessera/server/coordinator.h"
#include "tessera/server/store.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <thread>

namespace tessera::server {

using Clock = std::chrono::steady_clock;

struct LeaseInfo {
  uint64_t id = 0, job = 0, worker = 0;
  size_t unit = 0;
  Clock::time_point expires;
};

struct WorkerInfo {
  WorkerRow row;
  Clock::time_point last_seen;
  std::string state = "idle";  // idle, busy, lost, gone
  uint64_t units_done = 0, samples_done = 0;
  double render_seconds = 0;
};

struct Coordinator::Impl {
  explicit Impl(CoordinatorOptions o);

  CoordinatorOptions opt;
  Store store;
  BuildFingerprint fingerprint;

  std::mutex mu;
  std::condition_variable work_cv;  // new work, a lease expired, a job resumed, shutdown
  std::map<uint64_t, std::unique_ptr<JobState>> jobs;
  std::map<uint64_t, LeaseInfo> leases;
  std::map<uint64_t, WorkerInfo> workers;
  std::atomic<int> waiting_polls{0};
  bool stopping = false;
  std::thread reaper;
  Clock::time_point started = Clock::now();
  // For /metrics (under `mu`).
  struct Counters {
    uint64_t leased = 0, done = 0, expired = 0, failed = 0, duplicates = 0, bytes_in = 0, bytes_out = 0;
  } counters;
  Histogram lease_wait{{0.001, 0.01, 0.1, 0.5, 1, 2.5, 5, 10, 20, 30}};
  WebhookSender webhooks;
  RetentionState retention;  // (under `mu`)
  Histogram upload_seconds{{0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 1}};

  std::string bundle_path(const std::string& hash) const;
  std::string scene_dir(const std::string& hash) const;
  /// Under `mu`: the worker, loaded from the store after a restart; null if unknown.
  WorkerInfo* find_worker(uint64_t id);
  /// Under `mu`: ends a lease (the unit becomes available again unless done).
  void end_lease(std::map<uint64_t, LeaseInfo>::iterator it);
  /// Under `mu`: ends every lease for which `pred(const LeaseInfo&)` holds.
  template <class Pred>
  void end_leases_if(Pred pred) {
    for (auto l = leases.begin(); l != leases.end();) {
      auto next = std::next(l);
      if (pred(l->second)) end_lease(l);
      l = next;
    }
  }
  /// Under `mu`: persists a job's phase; a job that ended writes its image, drops its film and
  /// (with `notify`) has its webhook called.
  void save_phase(JobState& job, bool notify = true);
  std::string image_path(uint64_t job) const;
  /// A job from its row (plan, phase, times), with no results yet.
  std::unique_ptr<JobState> job_from_row(const JobRow& row) const;
  /// A job rebuilt from its row and every stored result (its film included).
  std::unique_ptr<JobState> rebuild_job(const JobRow& row);
  /// Under `mu`: 429 beyond --max-active-jobs queued and running jobs.
  Status check_active_jobs() const;
  /// Under `mu`: job status as JSON.
  nlohmann::json status_json(const JobState& job);
  /// Expires leases and marks silent workers lost, once a second.
  void reap_loop();
  /// A retention pass (retention.cpp); takes `mu` itself and deletes files outside it.
  nlohmann::json run_retention(double now);
  /// Under `mu`: 404 for a job that is not (or no longer) here, saying so if retention deleted it.
  Status missing_job(uint64_t id);
};

double wall_seconds();
Status internal_error(const std::exception& e);
inline Status unknown_job(uint64_t id) {
  return make_error(Code::NotFound, "unknown_job", "no job " + std::to_string(id));
}

}  // namespace tessera::server
