// The coordinator's shared state (one mutex guards all of it). Leases, results and phase changes
// are decided under it and appended to the group commit there, in that order; requests wait for
// their records to be durable after releasing it.
#pragma once

#include "background_queue.h"
#include "group_commit.h"
#include "job_state.h"
#include "metrics.h"
#include "retention.h"
#include "reaper.h"
#include "retention_plan.h"
#include "scheduler.h"
#include "webhooks.h"
#include "worker_state.h"
#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/tile_result.h"
#include "tessera/server/coordinator.h"
#include "tessera/server/store.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <map>
#include <mutex>
#include <thread>
#include <unordered_map>

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
  WorkerMemory memory;  // as its last heartbeat reported it
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
  std::unordered_map<uint64_t, uint32_t> leases_held;  // by worker: its entries in `leases`
  /// The one place a lease enters `leases` (replacing one of the same id); end_lease the one it leaves.
  void add_lease(const LeaseInfo& lease);
  void release_held(uint64_t worker) {
    if (--leases_held[worker] == 0) leases_held.erase(worker);
  }
  std::map<uint64_t, WorkerInfo> workers;
  uint64_t last_lease_id = 0;  // ids are never reused, also across restarts
  uint64_t workers_before_start = 0;  // ids up to this were registered with an earlier process
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
  /// Under `mu`: the worker; null if unknown (or registered before a restart and not adopted).
  WorkerInfo* find_worker(uint64_t id);
  /// Not under `mu`: a worker registered with the previous process keeps its id after a restart;
  /// its row is read from the store (outside the lock) the first time it is heard from.
  void adopt_worker(uint64_t id);
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
  /// Under `mu`: records a lease of the chosen unit and appends it to the log (the job starts with
  /// its first); the caller hands it out once `ticket` is durable, or ends it (end_lease_id).
  struct IssuedLease {
    Lease lease;
    uint64_t ticket = 0;
  };
  IssuedLease issue_lease(uint64_t worker, WorkerInfo& w, const UnitChoice& choice);
  /// Under `mu`: a lease for a worker that asks for one without waiting (with its result), if
  /// there is work it may take now.
  std::optional<IssuedLease> next_lease(uint64_t worker);
  /// Under `mu`: ends lease `id` if it is still in flight.
  void end_lease_id(uint64_t id) {
    if (auto it = leases.find(id); it != leases.end()) end_lease(it);
  }
  /// Under `mu`: the unit an uploaded result is for, once worker, job and unit check out.
  Result<size_t> check_result(uint64_t worker, const TileResult& result);
  /// Under `mu`: appends a checked result for `unit` (now committing) to the group commit; its
  /// ticket. Once durable, result_committed adds it to the job.
  uint64_t commit_result(JobState& job, size_t unit, uint64_t worker, const std::shared_ptr<TileResult>& result,
                         std::string_view bytes);
  /// Under `mu`, once durable (a group-commit callback): the result enters its job, which may then
  /// be done; `durable` false: the unit is open again.
  void result_committed(bool durable, uint64_t job, size_t unit, uint64_t worker, TileResult& result, size_t bytes);
  /// Under `mu`: appends the tile's checkpoint once `min_new` more passes are in its film (encoded
  /// by the writer, not under `mu`).
  void checkpoint_tile(JobState& job, uint32_t tile, uint32_t min_new);
  /// Under `mu`: stores what the job decided at its barriers since the last call, ahead of the
  /// passes that depend on it: adaptive passes' counts (appended to the group commit) and a guided
  /// job's new tree (encoded and written off the lock, then its row appended and its passes opened).
  void save_decisions(JobState& job);
  void save_pass_plans(JobState& job);
  void save_guides(JobState& job);
  /// Rebuilding: the job's stored trees and the training records of the pass it trains next.
  void restore_guide(JobState& job);
  std::string guide_path(const std::string& hash) const;
  /// Retention: the guide files no job names any more (and not just written), into `trash`.
  void collect_unused_guides(std::vector<std::filesystem::path>& trash);
  /// Not under `mu`: waits for a group-commit ticket; the error (500/507) if its batch failed.
  Status durable(uint64_t ticket);
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
  /// Under `mu`: the one place a job's phase changes (job_phases.cpp): times, leases, event, image
  /// and webhook, and the phase appended to the group commit (kept until durable, also across a
  /// full disk); returns its ticket. Throws std::logic_error for a transition that does not exist.
  [[nodiscard]] uint64_t change_phase(JobState& job, JobPhase to, const std::string& error = "");
  /// Under `mu`: appends a job's phase (times, error) to the group commit; its ticket.
  [[nodiscard]] uint64_t append_phase(const JobState& job);
  /// Under `mu`: a job that ended has its sums checkpointed and its image written in the
  /// background (off the lock); then its film is dropped and (with `notify`) its webhook called.
  /// An image a full disk kept from being written is tried again by the retention pass.
  void finish_job(JobState& job, bool notify);
  /// Under `mu` (job_denoise.cpp): a job whose last unit is in. Done; or, for a denoised job, first
  /// its raw image with the AOV layers and the denoised image are written off the lock on the
  /// `denoising` queue, and the job is Done once both are stored (with a denoise error, the raw one
  /// alone).
  void complete_job(JobState& job);
  std::string denoised_path(uint64_t job) const;
  /// Under `mu`: queues a preview-mode denoise of a running denoised job's film on `denoising`
  /// unless one is queued or the cached one is of the film as it is.
  void refresh_denoised_preview(JobState& job);
  /// The EXR header entries of a job's image.
  ImageAttributes image_attributes(const JobState& job) const;
  /// Not under `mu`: the job's image from its film, converted a band of rows at a time so that a
  /// large film never holds the lock for long; nullopt if the job or its film is gone.
  /// `consistent`: start again if the film changes between bands (an ended job's image); else a
  /// running job's preview may join bands a few results apart. `layers`, if given, receives the
  /// denoiser's AOV layers (denoise_layers()) from the same bands.
  std::optional<Image> film_image(uint64_t id, bool consistent, std::vector<ImageLayer>* layers = nullptr);
  /// Under `mu`: the job's webhook, if it has one, with its status.
  void send_webhook(const JobState& job);
  std::string image_path(uint64_t job) const;
  /// A job from its row (plan, phase, times), with no results yet.
  std::unique_ptr<JobState> job_from_row(const JobRow& row) const;
  /// A job rebuilt from its row and every stored result (its film included).
  std::unique_ptr<JobState> rebuild_job(const JobRow& row);
  /// The bundle unpacked into scene_dir (once; serialised per bundle) and the scene XML in it.
  Result<std::string> unpack_scene(const JobSettings& settings, const std::string& bundle_file);
  std::mutex unpack_mutexes_mu;
  std::map<std::string, std::weak_ptr<std::mutex>> unpack_mutexes;
  /// Stores (off `mu`, in a slot taken under it) and queues a planned job; its status.
  Result<JobStatus> add_job(const std::string& name, JobPlan plan);
  int submissions_in_flight = 0;  // slots add_job holds while it stores a job (`mu`)
  /// Under `mu`: 429 beyond --max-active-jobs queued, running and being stored jobs.
  Status check_active_jobs() const;
  /// Under `mu`: the job's status from memory; add_lease_counts completes it off the lock.
  JobStatus status_of(const JobState& job) const;
  /// The lease log's counts (store reads, so not under `mu`); left out if they cannot be read.
  void add_lease_counts(JobStatus& status);
  /// Expires leases and marks silent workers lost, once a second.
  void reap_loop();
  /// A retention pass (retention.cpp): a snapshot under `mu`, files measured off it, the plan
  /// (retention_plan.h, pure), jobs forgotten and bundles renamed away under `mu`, then their rows
  /// and files deleted off it. Nothing when the snapshot could not be taken.
  std::optional<RetentionReport> run_retention(double now);
  std::optional<std::vector<RetentionJob>> retention_snapshot();
  std::map<std::string, RetentionBundle> measure_retention_files(std::vector<RetentionJob>& snapshot);
  RetentionReport carry_out_retention(const RetentionPlan& plan, const std::vector<RetentionJob>& snapshot,
                                      const std::map<std::string, RetentionBundle>& bundles, double now);
  /// Under `mu`: drops a finished job from memory (its rows are deleted after the lock); false if
  /// it was retried since the snapshot.
  bool forget_expired_job(const RetentionJob& job);
  /// Off `mu`: the jobs' rows (leaving tombstones) and the bundles' rows deleted, pages vacuumed.
  /// The jobs whose rows were deleted (a failure is logged; the job is found again at start-up).
  std::vector<const RetentionJob*> delete_expired_rows(const std::vector<const RetentionJob*>& jobs,
                                                       const std::vector<std::string>& bundles, double now);
  /// Under `mu`: renames the bundle and its folder into `trash`; false if a job uses it again.
  bool move_expired_bundle(const std::string& hash, const RetentionBundle& bundle,
                           std::vector<std::filesystem::path>& trash);
  /// Under `mu`: 404 for a job that is not (or no longer) here, saying so if retention deleted it.
  Status missing_job(uint64_t id);

  // Image writing (finish_job): after everything its tasks touch, before `commits`, whose last
  // callbacks may still queue tasks.
  BackgroundQueue background;
  // The last member: its writer stops (committing what is queued, and running those records'
  // callbacks under `mu`) before anything it touches is destroyed.
  GroupCommit commits{store,
                      [this](const std::function<void()>& callbacks) {
                        std::lock_guard<std::mutex> lock(mu);
                        callbacks();
                      },
                      std::chrono::microseconds(int64_t(opt.commit_interval * 1e6))};
  // Denoising finished jobs, one at a time (complete_job). Destroyed first: a task queued but not
  // begun is dropped (the job is found complete again at start-up), a running one ends normally.
  BackgroundQueue denoising{BackgroundQueue::OnStop::DropQueued};
};

double wall_seconds();
/// Writes `bytes` to a temporary name, fsyncs, renames to `path` and fsyncs its directory: after a
/// crash the file is either complete or absent. Throws (DiskFullError on a full disk).
void write_file_durably(const std::string& path, const std::string& bytes);
/// The whole file; throws std::runtime_error naming it when it cannot be read.
std::string read_file(const std::string& path);

/// A tile's checkpoint as stored: tile_result.h bytes (pass: its last pass; samples 0..sample_end).
std::string encode_checkpoint(uint64_t job, const JobState::Checkpoint& cp);
Status internal_error(const std::exception& e);
inline Status unknown_job(uint64_t id) {
  return make_error(Code::NotFound, "unknown_job", "no job " + std::to_string(id));
}

}  // namespace tessera::server
