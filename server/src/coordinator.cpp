// Construction, resume after a restart, health, metrics and shutdown.
#include "coordinator_impl.h"
#include "disk_full.h"
#include "event_log.h"
#include "upload_spool.h"

#include <spdlog/spdlog.h>

#include <filesystem>

namespace tessera::server {

namespace fs = std::filesystem;

double wall_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

Status internal_error(const std::exception& e) {
  if (is_disk_full(e)) return disk_full_status(e);
  return make_error(Code::Internal, "internal", e.what());
}

int http_status(Code code) {
  switch (code) {
    case Code::Ok: return 200;
    case Code::NotYet: return 202;
    case Code::BadRequest: return 400;
    case Code::NotFound: return 404;
    case Code::Conflict: return 409;
    case Code::Gone: return 410;
    case Code::PayloadTooLarge: return 413;
    case Code::Unprocessable: return 422;
    case Code::TooManyRequests: return 429;
    case Code::Unavailable: return 503;
    case Code::Internal: return 500;
    case Code::InsufficientStorage: return 507;
  }
  return 500;
}

namespace {
std::string prepare_data_dir(const std::string& dir) {
  for (const char* sub : {"bundles", "scenes", "tmp", "images", "guides"}) fs::create_directories(fs::path(dir) / sub);
  clear_spool((fs::path(dir) / "tmp").string());  // (uploads a crash cut short)
  return (fs::path(dir) / "state.sqlite").string();
}
}  // namespace

Coordinator::Impl::Impl(CoordinatorOptions o)
    : opt(std::move(o)), store(prepare_data_dir(opt.data_dir)), fingerprint(build_fingerprint()) {}

std::string Coordinator::Impl::bundle_path(const std::string& hash) const {
  return (fs::path(opt.data_dir) / "bundles" / (hash + ".bundle")).string();
}
std::string Coordinator::Impl::guide_path(const std::string& hash) const {
  return (fs::path(opt.data_dir) / "guides" / (hash + ".guide")).string();
}
std::string Coordinator::Impl::scene_dir(const std::string& hash) const {
  return (fs::path(opt.data_dir) / "scenes" / hash).string();
}
std::string Coordinator::Impl::image_path(uint64_t job) const {
  return (fs::path(opt.data_dir) / "images" / (std::to_string(job) + ".exr")).string();
}
std::string Coordinator::Impl::denoised_path(uint64_t job) const {
  return (fs::path(opt.data_dir) / "images" / (std::to_string(job) + ".denoised.exr")).string();
}

namespace {

// A job that ended has its image on disk: only its bookkeeping is rebuilt, not its film.
std::unique_ptr<JobState> ended_job(Store& store, std::unique_ptr<JobState> job) {
  store.for_each_result(job->id(), [&](ResultRow&& r) {
    if (job->has_unit(r.tile, r.pass)) job->mark_done(job->unit(r.tile, r.pass), r.worker);
  }, /*with_data=*/false);
  if (job->phase() == JobPhase::Done && job->done_units() < job->num_units()) job->restore_converged();
  job->release_film();
  return job;
}

}  // namespace

Coordinator::Coordinator(CoordinatorOptions options) : impl_(std::make_unique<Impl>(std::move(options))) {
  Impl& s = *impl_;
  // Resume: every job's acknowledged passes go back into its film; leases in flight died with the
  // previous process, so their units are simply available again.
  size_t resumed = 0, passes = 0;
  // (Under the lock: the group commit's callbacks and image writes take it too.)
  MutexLock lock(s.mu);
  s.leases.continue_after(s.store.last_lease_seq());
  s.workers.registered_before(s.store.last_worker_id());
  for (JobRow& row : s.store.jobs()) {
    JobPhase phase;
    if (!parse_phase(row.state, phase)) phase = JobPhase::Failed;
    if (is_terminal(phase) && fs::exists(s.image_path(row.id))) {
      s.jobs.add(ended_job(s.store, s.job_from_row(row)));
      continue;
    }
    JobState& job = s.jobs.add(s.rebuild_job(row));
    s.save_decisions(job);
    s.fold_splats(job);  // (its stored splats, a chunk at a time)
    passes += job.done_units();
    if (!is_terminal(job.phase()) && job.complete()) {  // its last result landed before a crash
      s.complete_job(job);
    } else if (is_terminal(job.phase())) {
      s.finish_job(job, /*notify=*/false);  // it ended before its image was written
    } else {
      ++resumed;
      s.hold_open_leases(job);
    }
  }
  // /metrics counts from what the data dir holds, so "done" never exceeds "leased" after a restart.
  const auto [leased, done] = s.store.lease_and_result_counts();
  s.metrics.counters.leased = leased;
  s.metrics.counters.done = done;
  if (s.jobs.size() > 0)
    spdlog::info("coordinator: {} jobs in {}, {} resumed with {} acknowledged passes", s.jobs.size(), s.opt.data_dir,
                 resumed, passes);
  s.reaper = std::thread([&s] { s.reap_loop(); });
}

Coordinator::~Coordinator() {
  shutdown();
  if (impl_->reaper.joinable()) impl_->reaper.join();
}

void Coordinator::shutdown() {
  MutexLock lock(impl_->mu);
  impl_->stopping = true;
  impl_->work_cv.notify_all();
}

std::string Coordinator::metrics() {
  Impl& s = *impl_;
  MetricsSnapshot snap;
  {
    MutexLock lock(s.mu);
    snap.jobs_by_phase = s.jobs.count_by_phase();
    snap.workers_by_state = s.workers.count_by_state();
    for (const auto& [id, w] : s.workers.all())
      snap.workers.push_back({id, w.row.name, w.render_seconds > 0 ? double(w.samples_done) / w.render_seconds : 0.0,
                              w.memory.scene_bytes});
    snap.leases_active = s.leases.size();
    snap.retention = s.retention;
  }
  const GroupCommit::Stats commits = s.commits.stats();
  snap.commits = commits.commits;
  snap.failed_commits = commits.failed_batches;
  snap.committed_records = commits.records;
  snap.webhooks_delivered = s.webhooks.delivered();
  snap.webhooks_failed = s.webhooks.failed();
  return s.metrics.render(snap);  // (rendered off the lock)
}

Health Coordinator::health() {
  MutexLock lock(impl_->mu);
  return {impl_->stopping ? "stopping" : "ok", impl_->fingerprint.version, impl_->jobs.active(), impl_->leases.size(),
          std::chrono::duration<double>(Clock::now() - impl_->started).count()};
}

}  // namespace tessera::server
