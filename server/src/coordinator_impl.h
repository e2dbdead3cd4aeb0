// The coordinator's parts and what joins them. The parts own their invariants and are unit-tested
// alone: the job registry (job_registry.h), the lease table (lease_table.h), the worker registry
// (worker_registry.h), the farm's metrics (farm_metrics.h). One mutex, `mu`, guards the first
// three (a lease, a result or a phase change touches all of them at once); the compiler checks it
// (core/mutex.h): their state is TESSERA_GUARDED_BY(mu) and what runs with it held is
// TESSERA_REQUIRES(mu). Leases, results and phase changes are decided under it and appended to the
// group commit there, in that order; requests wait for their records to be durable after releasing
// it. No disk I/O, encoding or decoding is done under it.
#pragma once

#include "background_queue.h"
#include "farm_metrics.h"
#include "group_commit.h"
#include "job_registry.h"
#include "job_state.h"
#include "lease_table.h"
#include "retention.h"
#include "reaper.h"
#include "retention_plan.h"
#include "scheduler.h"
#include "webhooks.h"
#include "worker_registry.h"
#include "unit_upload.h"
#include "tessera/core/mutex.h"
#include "tessera/farm/build_fingerprint.h"
#include "tessera/farm/tile_result.h"
#include "tessera/server/coordinator.h"
#include "tessera/server/store.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <map>
#include <thread>

namespace tessera::server {

struct Coordinator::Impl {
  class BundleHold;

  explicit Impl(CoordinatorOptions o);

  CoordinatorOptions opt;
  Store store;
  BuildFingerprint fingerprint;

  Mutex mu;
  std::condition_variable_any work_cv;  // new work, a lease expired, a job resumed, shutdown
  JobRegistry jobs TESSERA_GUARDED_BY(mu);
  LeaseTable leases TESSERA_GUARDED_BY(mu);
  WorkerRegistry workers TESSERA_GUARDED_BY(mu);
  FarmMetrics metrics;  // (atomics and self-locking histograms: updated off the lock)
  RetentionState retention TESSERA_GUARDED_BY(mu);
  bool stopping TESSERA_GUARDED_BY(mu) = false;
  std::atomic<int> waiting_polls{0};
  std::thread reaper;
  const Clock::time_point started = Clock::now();
  WebhookSender webhooks;

  std::string bundle_path(const std::string& hash) const;
  std::string scene_dir(const std::string& hash) const;
  std::string guide_path(const std::string& hash) const;
  std::string image_path(uint64_t job) const;
  std::string denoised_path(uint64_t job) const;
  /// Silence after which a worker is dead and a lease expires: kMissedHeartbeats intervals.
  Clock::duration dead_after() const {
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(opt.heartbeat_interval * kMissedHeartbeats));
  }

  // Workers (coordinator_workers.cpp).
  /// A worker registered with the previous process keeps its id after a restart; its row is read
  /// from the store (off the lock) the first time it is heard from.
  void adopt_worker(uint64_t id) TESSERA_EXCLUDES(mu);
  /// The one place a worker's state changes (worker_registry.h), with its event; a lost worker's
  /// leases end.
  void set_worker_state(uint64_t id, WorkerInfo& w, WorkerState to) TESSERA_REQUIRES(mu);
  /// The worker was heard from; a lost one is live again.
  void saw_worker(uint64_t id, WorkerInfo& w) TESSERA_REQUIRES(mu);
  /// Idle or Busy by whether it holds a lease (a live worker only).
  void update_busy(uint64_t id, WorkerInfo& w) TESSERA_REQUIRES(mu);

  // Leases (coordinator_leases.cpp).
  /// The scheduler's choice (scheduler.h) for a worker asking for work.
  std::optional<UnitChoice> choose_unit_for(uint64_t worker) TESSERA_REQUIRES(mu);
  /// How long a lease of the job runs before it is overdue (none before its first unit is in).
  std::optional<Clock::duration> speculation_threshold(const JobState& job) const TESSERA_REQUIRES(mu);
  /// Records a lease of the chosen unit and appends it to the log (the job starts with its first);
  /// the caller hands it out once `ticket` is durable, or ends it (end_lease).
  struct IssuedLease {
    Lease lease;
    uint64_t ticket = 0;
  };
  IssuedLease issue_lease(uint64_t worker, WorkerInfo& w, const UnitChoice& choice) TESSERA_REQUIRES(mu);
  /// A lease for a worker that asks for one without waiting (with its result), if there is work it
  /// may take now.
  std::optional<IssuedLease> next_lease(uint64_t worker) TESSERA_REQUIRES(mu);
  /// The one place a lease enters, and the one it leaves (the unit is available again unless done).
  void add_lease(const LeaseInfo& lease) TESSERA_REQUIRES(mu);
  void end_lease(uint64_t id) TESSERA_REQUIRES(mu);
  void end_leases(const std::vector<uint64_t>& ids) TESSERA_REQUIRES(mu) {
    for (uint64_t id : ids) end_lease(id);
  }
  /// A lease the worker reports holding is kept (or re-adopted); false: drop it.
  bool keep_lease(uint64_t worker, const HeldLease& held) TESSERA_REQUIRES(mu);
  /// Declares silent workers dead (their leases re-issued) and expires leases.
  void reap_leases_and_workers() TESSERA_REQUIRES(mu);
  /// The leases logged but not acknowledged before a restart, held for their workers.
  void hold_open_leases(JobState& job) TESSERA_REQUIRES(mu);
  /// Expires leases and marks silent workers lost, once a second; runs retention passes.
  void reap_loop() TESSERA_EXCLUDES(mu);

  // Results (coordinator_results.cpp).
  /// Whether an upload's records are valid records of its job's point map (none: nothing to check).
  Status check_point_records(const UnitUpload& upload) TESSERA_EXCLUDES(mu);
  /// The unit an uploaded result is for, once worker, job and unit (and the result's kind) check out.
  Result<size_t> check_result(uint64_t worker, const UnitUpload& upload) TESSERA_REQUIRES(mu);
  Status check_tile_result(const JobState& job, size_t unit, const TileResult& result);
  Status check_splat_result(const JobState& job, size_t unit, const SplatResult& result);
  /// Appends a checked result for `unit` (now committing) to the group commit; its ticket. Once
  /// durable, result_committed adds it to the job.
  uint64_t commit_result(JobState& job, size_t unit, uint64_t worker, const UnitUpload& upload,
                         const std::shared_ptr<const UploadBytes>& bytes) TESSERA_REQUIRES(mu);
  /// Once durable (a group-commit callback): the result enters its job, which may then be done;
  /// `durable` false: the unit is open again.
  void result_committed(bool durable, uint64_t job, size_t unit, uint64_t worker, const UnitUpload& upload, size_t bytes)
      TESSERA_REQUIRES(mu);
  /// A second result for a done unit is dropped, and compared with the first when its digest was
  /// kept (a mismatch is counted and logged as an error).
  void check_duplicate(JobState& job, size_t unit, uint64_t worker, const Sha256Digest& digest) TESSERA_REQUIRES(mu);
  /// Folds the job's ready splats on the background queue, a chunk per hold of `mu`; completes the
  /// job once its last are in.
  void fold_splats(JobState& job) TESSERA_REQUIRES(mu);
  /// Appends the tile's checkpoint once `min_new` more passes are in its film (encoded by the
  /// writer, not under `mu`).
  void checkpoint_tile(JobState& job, uint32_t tile, uint32_t min_new) TESSERA_REQUIRES(mu);
  /// Not under `mu`: waits for a group-commit ticket; the error (500/507) if its batch failed.
  Status durable(uint64_t ticket) TESSERA_EXCLUDES(mu);

  // A job's decisions and artifacts (coordinator.cpp).
  /// Stores what the job decided at its barriers since the last call, ahead of the passes that
  /// depend on it: adaptive passes' counts (appended to the group commit) and a new artifact
  /// (encoded and written off the lock, then its row appended and its passes opened).
  void save_decisions(JobState& job) TESSERA_REQUIRES(mu);
  void save_pass_plans(JobState& job) TESSERA_REQUIRES(mu);
  void save_artifacts(JobState& job) TESSERA_REQUIRES(mu);
  /// Rebuilding: the job's stored artifacts and the records of the passes that feed the next.
  void restore_artifacts(JobState& job);
  /// Retention: the guide files no job names any more (and not just written), into `trash`.
  void collect_unused_guides(std::vector<std::filesystem::path>& trash);
  /// Deletes a spent point map's file unless a row names it or it was written again since `written`.
  void remove_spent_artifact(const std::string& hash, std::filesystem::file_time_type written) TESSERA_EXCLUDES(mu);

  // Phases (job_phases.cpp, job_denoise.cpp).
  /// The one place a job's phase changes: times, leases, event, image and webhook, and the phase
  /// appended to the group commit (kept until durable, also across a full disk); its ticket.
  /// Throws std::logic_error for a transition that does not exist.
  [[nodiscard]] uint64_t change_phase(JobState& job, JobPhase to, const std::string& error = "") TESSERA_REQUIRES(mu);
  /// Appends a job's phase (times, error) to the group commit; its ticket.
  [[nodiscard]] uint64_t append_phase(const JobState& job) TESSERA_REQUIRES(mu);
  /// A job that ended has its sums checkpointed and its image written in the background (off the
  /// lock); then its film is dropped and (with `notify`) its webhook called. An image a full disk
  /// kept from being written is tried again by the retention pass.
  void finish_job(JobState& job, bool notify) TESSERA_REQUIRES(mu);
  /// A job whose last unit is in. Done; or, for a denoised job, first its raw image with the AOV
  /// layers and the denoised image are written off the lock on the `denoising` queue, and the job
  /// is Done once both are stored (with a denoise error, the raw one alone).
  void complete_job(JobState& job) TESSERA_REQUIRES(mu);
  /// Queues a preview-mode denoise of a running denoised job's film on `denoising` unless one is
  /// queued or the cached one is of the film as it is.
  void refresh_denoised_preview(JobState& job) TESSERA_REQUIRES(mu);
  /// The EXR header entries of a job's image.
  ImageAttributes image_attributes(const JobState& job) const;
  /// The job's image from its film, converted a band of rows at a time so that a large film never
  /// holds the lock for long; nullopt if the job or its film is gone. `consistent`: start again if
  /// the film changes between bands (an ended job's image); else a running job's preview may join
  /// bands a few results apart. `layers`, if given, receives the denoiser's AOV layers
  /// (denoise_layers()) from the same bands.
  std::optional<Image> film_image(uint64_t id, bool consistent, std::vector<ImageLayer>* layers = nullptr)
      TESSERA_EXCLUDES(mu);
  /// The job's webhook, if it has one, with its status.
  void send_webhook(const JobState& job) TESSERA_REQUIRES(mu);

  // Jobs (coordinator_jobs.cpp).
  /// A job from its row (plan, phase, times), with no results yet.
  std::unique_ptr<JobState> job_from_row(const JobRow& row) const;
  /// A job rebuilt from its row and every stored result (its film included).
  std::unique_ptr<JobState> rebuild_job(const JobRow& row);
  /// Checks and stores an uploaded bundle; `written` says whether this call wrote its file (it was
  /// not stored before), so a submission refused later knows the bundle is its own to delete.
  /// The bundle is held by `hold` (taken before its file is touched or written).
  Result<SceneUpload> store_bundle(const std::string& bundle, bool& written, BundleHold& hold);
  /// Deletes a bundle this request wrote for a job that was refused (file, unpacked scene, row),
  /// unless a job, or a submission other than the caller's (which holds it once), uses it
  /// (retention.cpp).
  void discard_bundle(const std::string& hash) TESSERA_EXCLUDES(mu);
  /// Whether a job, or more than `own_holds` submissions in flight, use the bundle.
  bool bundle_in_use(const std::string& hash, int own_holds) const TESSERA_REQUIRES(mu);
  /// Renames the bundle's file and unpacked scene into DATA_DIR/tmp, adding them to `trash`.
  void move_bundle_aside(const std::string& hash, const char* why, std::vector<std::filesystem::path>& trash)
      TESSERA_REQUIRES(mu);
  // Submissions in flight per bundle (BundleHold): a refused one's bundle is kept while another uses it.
  std::map<std::string, int> bundle_holds TESSERA_GUARDED_BY(mu);
  /// The bundle unpacked into scene_dir (once; serialised per bundle) and the scene XML in it.
  Result<std::string> unpack_scene(const JobSettings& settings, const std::string& bundle_file);
  std::mutex unpack_mutexes_mu;  // (guards only the map of per-bundle mutexes below)
  std::map<std::string, std::weak_ptr<std::mutex>> unpack_mutexes;
  /// Stores (off `mu`, in a slot taken under it) and queues a planned job; its status.
  Result<JobStatus> add_job(const std::string& name, JobPlan plan) TESSERA_EXCLUDES(mu);
  /// The job's status from memory; add_lease_counts completes it off the lock.
  JobStatus status_of(const JobState& job) TESSERA_REQUIRES(mu);
  /// The lease log's counts (store reads, so not under `mu`); left out if they cannot be read.
  void add_lease_counts(JobStatus& status) TESSERA_EXCLUDES(mu);
  /// 404 for a job that is not (or no longer) here, saying so if retention deleted it.
  Status missing_job(uint64_t id);

  // Retention (retention.cpp): a snapshot under `mu`, files measured off it, the plan
  // (retention_plan.h, pure), jobs forgotten and bundles renamed away under `mu`, then their rows
  // and files deleted off it. Nothing when the snapshot could not be taken.
  std::optional<RetentionReport> run_retention(double now) TESSERA_EXCLUDES(mu);
  std::optional<std::vector<RetentionJob>> retention_snapshot() TESSERA_EXCLUDES(mu);
  std::map<std::string, RetentionBundle> measure_retention_files(std::vector<RetentionJob>& snapshot);
  RetentionReport carry_out_retention(const RetentionPlan& plan, const std::vector<RetentionJob>& snapshot,
                                      const std::map<std::string, RetentionBundle>& bundles, double now)
      TESSERA_EXCLUDES(mu);
  /// Drops a finished job from memory (its rows are deleted after the lock); false if it was
  /// retried since the snapshot.
  bool forget_expired_job(const RetentionJob& job) TESSERA_REQUIRES(mu);
  /// Off `mu`: the jobs' rows (leaving tombstones) and the bundles' rows deleted, pages vacuumed.
  /// The jobs whose rows were deleted (a failure is logged; the job is found again at start-up).
  std::vector<const RetentionJob*> delete_expired_rows(const std::vector<const RetentionJob*>& jobs,
                                                       const std::vector<std::string>& bundles, double now);
  /// Renames the bundle and its folder into `trash`; false if a job uses it again.
  bool move_expired_bundle(const std::string& hash, const RetentionBundle& bundle,
                           std::vector<std::filesystem::path>& trash) TESSERA_REQUIRES(mu);

  // Image writing (finish_job): after everything its tasks touch, before `commits`, whose last
  // callbacks may still queue tasks.
  BackgroundQueue background;
  // The last member but one: its writer stops (committing what is queued, and running those
  // records' callbacks under `mu`) before anything it touches is destroyed.
  GroupCommit commits{store,
                      [this](const std::function<void()>& callbacks) {
                        MutexLock lock(mu);
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
/// A stored checkpoint's sums: one tile result per film of the job (the first with its tile state).
[[nodiscard]] bool decode_checkpoint(std::string_view bytes, std::vector<TileResult>& films, std::string& error);
Status internal_error(const std::exception& e);
inline Status unknown_job(uint64_t id) {
  return make_error(Code::NotFound, "unknown_job", "no job " + std::to_string(id));
}

// A submission's claim on a bundle, from before its file is written or touched until the job is
// added or refused: a concurrent submission of the same bundle that is refused keeps it.
class Coordinator::Impl::BundleHold {
 public:
  explicit BundleHold(Coordinator::Impl& s) : s_(s) {}
  ~BundleHold();
  BundleHold(const BundleHold&) = delete;
  BundleHold& operator=(const BundleHold&) = delete;
  /// Claims `hash` (once per hold).
  void take(const std::string& hash);

 private:
  Coordinator::Impl& s_;
  std::string hash_;
};

}  // namespace tessera::server
