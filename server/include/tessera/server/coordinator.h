// The coordinator's services: scenes, jobs, workers and leases. HTTP handlers (http_api.cpp) only
// parse a request, call one of these and map the Result; the tests call them directly too.
//
// Work unit = (tile, pass). Units are leased pass-major (every tile's first pass before any second
// pass: a quick preview of the whole frame), jobs by priority then submission. A tile's passes are
// added to the job's Film in pass order whatever order they arrive in, which keeps the stitched
// image bit-identical to `tessera render` (render/renderer.h).
#pragma once

#include "tessera/farm/bundle.h"
#include "tessera/farm/mapped_file.h"
#include "tessera/farm/farm_status.h"
#include "tessera/farm/job_status.h"
#include "tessera/farm/protocol.h"
#include "tessera/server/status.h"


#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace tessera::server {

struct CoordinatorOptions {
  std::string data_dir = "tessera-data";
  // Workers heartbeat this often (seconds). One silent for 3 intervals (kMissedHeartbeats) is
  // declared dead and its leases are re-issued at once; a lease its worker stops reporting expires
  // after the same time; after a restart, the leases of the previous process are held that long
  // for their workers to re-adopt them.
  double heartbeat_interval = 2;
  double max_poll_wait = 30;      // upper bound of a lease long poll
  // Group commit (group_commit.h): under load, a state-database commit starts at most this often
  // (seconds), taking every lease, result and phase change decided meanwhile: fewer fsyncs per
  // unit for at most this much more latency. 0: commit as soon as the previous commit ends.
  double commit_interval = 0.004;
  // Threads the coordinator denoises a finished job's image with (job field `denoise`), one job
  // at a time, off its lock; the image does not depend on it. 0: every core.
  int denoise_threads = 1;
  int max_waiting_polls = 16;     // concurrent long polls; more get 204 at once (never starve clients)
  // Idle workers get a copy of a job's oldest overdue unit once it has no unleased one
  // (scheduler.h); the first result wins and a later one must match it bit for bit.
  bool speculate = true;
  // A lease is overdue once it has run this many times the job's median unit render time (and
  // only once one unit of the job is in); 0: at once.
  double speculate_after = 3;
  int worker_failure_limit = 2;   // failures of one worker on one job before it is kept off the job
  int failed_workers_limit = 3;   // distinct workers failing a job before the job fails
  JobLimits limits;
  BundleLimits bundle_limits;
  uint64_t max_upload_bytes = uint64_t(4) << 30;
  int max_active_jobs = 10000;  // queued + running; more are refused with 429 until some end
  // Retention (retention.h): finished jobs older than this many days since they ended are deleted
  // with their results and image; 0 keeps them forever.
  double retain_days = 0;
  // Above this many bytes of stored results, images and bundles, the oldest finished jobs (and
  // bundles no job uses) are deleted until under; 0: no limit.
  uint64_t retain_bytes = 0;
  // Seconds between retention passes (which also retry images a full disk kept from being
  // written); the first runs at start-up. 0: only on apply_retention().
  double maintenance_interval = 60;
  // A program that plans a job's scene in a child process (`PROGRAM --plan-scene`, i.e.
  // tessera-server itself), so the memory of loading it goes back to the system; empty: in this
  // process (tests).
  std::string scene_planner;
  std::vector<std::string> webhook_allow;  // URL prefixes a job's webhook must start with; empty: any
};

/// What a retention pass did: jobs and bundles deleted, bytes freed, bytes the data dir still holds.
struct RetentionReport {
  uint64_t deleted_jobs = 0, deleted_bundles = 0, freed_bytes = 0, data_bytes = 0;
};

struct ImageBytes {
  std::string bytes, content_type;
};

/// A stored file to send as it is: streamed from disk, never read whole into memory.
struct StoredFile {
  std::string path;
  uint64_t size = 0;
};

/// An upload's bytes: in memory, or (a large one) spooled to a file as it arrived and mapped, never
/// read whole into the heap. Shared by whatever still needs them (the group commit's writer).
struct UploadBytes {
  std::string memory;
  std::shared_ptr<const MappedFile> file;
  std::string_view view() const { return file ? file->bytes() : std::string_view(memory); }
};

/// What an upload may weigh, and what it is (named in a 413's message).
struct BodyLimit {
  uint64_t bytes = 0;
  std::string what;
};

class Coordinator {
 public:
  /// Opens the data directory and resumes every unfinished job. Throws std::runtime_error with the
  /// reason if the data directory cannot be used.
  explicit Coordinator(CoordinatorOptions options);
  ~Coordinator();
  Coordinator(const Coordinator&) = delete;
  Coordinator& operator=(const Coordinator&) = delete;

  // Scenes: bundles stored content-addressed by SHA-256.
  Result<SceneUpload> upload_scene(const std::string& bundle);
  /// Path of the stored bundle file.
  Result<std::string> scene_bundle_path(const std::string& hash);
  /// The stored bundle (what workers download).
  Result<StoredFile> scene_bundle_file(const std::string& hash);
  /// An artifact a job renders with (a guided job's guide, sequence/guide_artifact.h bytes) by its
  /// SHA-256.
  Result<StoredFile> guide_file(const std::string& hash);

  // Jobs. `bundle` non-empty: uploaded in the same request (the settings' scene may be empty).
  // With "frames": "A-B" (or [A, B]) in the settings, one job per frame N in A..B, each with
  // `-D frame=N` and its own image; the answer has a status per frame. A frame that fails to
  // load cancels the frames already queued and names itself in the error.
  Result<JobSubmission> submit_job(const JobRequest& request, const std::string& bundle);
  Result<JobStatus> job_status(uint64_t id);
  Result<std::vector<JobSummary>> list_jobs();
  /// format: exr, png or pfm. The partial image while running.
  /// `denoised`: the denoised image of a job with `denoise`, once it is done (202 before).
  Result<ImageBytes> job_image(uint64_t id, const std::string& format, bool denoised = false);
  Status cancel_job(uint64_t id);
  /// Operating a job: a new priority (any time), or a failed/cancelled job queued again with the
  /// passes it already has (its failure counts cleared).
  Status set_priority(uint64_t id, int priority);
  Status retry_job(uint64_t id);

  // Workers: the farm's protocol types in and out (JSON is the HTTP layer's).
  /// 409 for a build whose fingerprint differs from the coordinator's.
  Result<Registration> register_worker(const WorkerHello& hello);
  /// Waits up to `wait_seconds` (bounded by max_poll_wait) for work; nothing when there is none.
  Result<std::optional<Lease>> lease(uint64_t worker, double wait_seconds);
  /// The leases the worker still holds: each is kept alive (or re-adopted after a restart); the
  /// answer lists those the coordinator no longer wants (to drop). The memory it reports is shown
  /// in its status until the next heartbeat.
  Result<std::vector<uint64_t>> heartbeat(uint64_t worker, const Heartbeat& heartbeat);
  /// The largest result `worker` may upload for `lease`: what its unit's sums can take (tile area,
  /// AOV sums, training records); for a lease this coordinator does not know (a restart), the
  /// largest any unit within its limits can take.
  BodyLimit result_limit(uint64_t worker, uint64_t lease);
  /// A tile result (tile_result.h bytes). Accepted once per unit: a duplicate is acknowledged and
  /// dropped. Valid without a live lease too (a worker finishing across a coordinator restart).
  /// Answered once durable. With `next`, the answer also carries the worker's next lease (none
  /// when there is no work it may take now), logged in the same commit as the result.
  Result<ResultAck> upload_result(uint64_t worker, uint64_t lease, std::shared_ptr<const UploadBytes> bytes,
                                  bool next = false);
  Result<ResultAck> upload_result(uint64_t worker, uint64_t lease, std::string_view bytes, bool next = false) {
    return upload_result(worker, lease, std::make_shared<const UploadBytes>(UploadBytes{std::string(bytes), nullptr}), next);
  }
  /// Where uploads are spooled while they arrive (data-dir/tmp).
  std::string spool_dir() const;
  /// The worker could not render the lease (`reason`, at most 2000 characters kept).
  Status fail_lease(uint64_t worker, uint64_t lease, const std::string& reason);
  Status sign_off(uint64_t worker);
  /// Draining: the worker finishes what it renders and gets no more work (its lease polls are
  /// answered 410, on which tessera-worker signs off and exits).
  Status drain_worker(uint64_t worker);
  Result<std::vector<WorkerStatus>> list_workers();

  Health health();
  /// Prometheus text format: jobs and workers by state, passes leased/done/expired/failed,
  /// lease-wait and upload latency histograms, bytes in and out, per-worker samples/s.
  std::string metrics();
  /// One retention pass now (as the reaper runs every maintenance_interval), judged at wall time
  /// `now` (0: the real time; tests pass a later one instead of sleeping).
  Result<RetentionReport> apply_retention(double now = 0);
  /// Wakes every long poll and refuses new ones (503); called on SIGTERM.
  void shutdown();

 private:
  struct Impl;
  Result<JobSubmission> submit_frames(const JobRequest& request, const std::string& bundle);
  Result<JobStatus> submit_one(JobSettings settings, const std::string& bundle);
  std::unique_ptr<Impl> impl_;
};

}  // namespace tessera::server
