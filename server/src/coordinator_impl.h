// The coordinator's shared state (one mutex guards all of it; SQLite writes happen under it,
// which serialises them as SQLite would anyway).
#pragma once

#include "job_state.h"
#include "metrics.h"
#include "retention.h"
#include "scheduler.h"
#include "webhooks.h"
#include "worker_state.h"
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
  WorkerState state = WorkerState::Idle;
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
    uint64_t leased = 0, done = 0, expired = 0, failed = 0, duplicates = 0, speculative = 0, mismatched = 0;
    uint64_t bytes_in = 0, bytes_out = 0;
  } counters;
  Histogram lease_wait{{0.001, 0.01, 0.1, 0.5, 1, 2.5, 5, 10, 20, 30}};
  WebhookSender webhooks;
  RetentionState retention;  // (under `mu`)
  Histogram upload_seconds{{0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 1}};

  std::string bundle_path(const std::string& hash) const;
  std::string scene_dir(const std::string& hash) const;
  /// Under `mu`: the worker, loaded from the store after a restart; null if unknown.
  WorkerInfo* find_worker(uint64_t id);
  /// Under `mu`: the one place a worker's state changes (worker_state.h), with its event.
  void set_worker_state(uint64_t id, WorkerInfo& w, WorkerState to);
  /// Under `mu`: the worker was heard from; a lost one is live again.
  void saw_worker(uint64_t id, WorkerInfo& w);
  /// Under `mu`: Idle or Busy by whether it holds a lease (a live worker only).
  void update_busy(uint64_t id, WorkerInfo& w);
  /// Silence after which a worker is dead and a lease expires: kMissedHeartbeats intervals.
  Clock::duration dead_after() const {
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(opt.heartbeat_interval * kMissedHeartbeats));
  }
  /// Under `mu`: the scheduler's choice (scheduler.h) for a worker asking for work.
  std::optional<UnitChoice> choose_unit_for(uint64_t worker);
  /// Under `mu`: logs and hands out a lease of the chosen unit (the job starts with its first).
  Result<nlohmann::json> issue_lease(uint64_t worker, WorkerInfo& w, const UnitChoice& choice);
  /// Under `mu`: a second result for a done unit is dropped, and compared with the first when its
  /// digest was kept (a mismatch is counted and logged as an error).
  void check_duplicate(JobState& job, size_t unit, uint64_t worker, const FilmTile& film);
  /// Under `mu`: a lease the worker reports holding is kept (or re-adopted); false: drop it.
  bool keep_lease(uint64_t worker, const HeldLease& held);
  /// Under `mu`: declares silent workers dead (their leases re-issued) and expires leases.
  void reap_leases_and_workers();
  /// Under `mu`: the leases logged but not acknowledged before a restart, held for their workers.
  void hold_open_leases(JobState& job);
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
  /// Under `mu`: the one place a job's phase changes (job_phases.cpp): times, persistence, leases,
  /// event, image and webhook. Throws (the job unchanged) when the change cannot be persisted, or
  /// std::logic_error for a transition that does not exist.
  void change_phase(JobState& job, JobPhase to, const std::string& error = "");
  /// Under `mu`: persists a job's phase, then finish_job.
  void save_phase(JobState& job, bool notify = true);
  /// Under `mu`: a job that ended writes its image, drops its film and (with `notify`) has its
  /// webhook called.
  void finish_job(JobState& job, bool notify);
  std::string image_path(uint64_t job) const;
  /// A job from its row (plan, phase, times), with no results yet.
  std::unique_ptr<JobState> job_from_row(const JobRow& row) const;
  /// A job rebuilt from its row and every stored result (its film included).
  std::unique_ptr<JobState> rebuild_job(const JobRow& row);
  /// The bundle unpacked into scene_dir (once; serialised per bundle) and the scene XML in it.
  Result<std::string> unpack_scene(const JobSettings& settings, const std::string& bundle_file);
  std::mutex unpack_mutexes_mu;
  std::map<std::string, std::weak_ptr<std::mutex>> unpack_mutexes;
  /// Takes `mu`: stores and queues a planned job; its status.
  Result<nlohmann::json> add_job(const std::string& name, JobPlan plan);
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
