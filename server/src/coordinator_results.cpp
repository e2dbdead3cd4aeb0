// Results: an upload is checked against its unit, committed with the group commit (the tile's
// checkpoint in its place when it can be), added to its job once durable, and answered; a copy of
// a unit already in is a duplicate, compared with the accepted one. Failed leases count against
// the worker and the job.
#include "coordinator_impl.h"
#include "event_log.h"

#include "tessera/farm/splat_result.h"
#include "tessera/farm/tile_result.h"

#include <spdlog/spdlog.h>

#include <filesystem>

namespace tessera::server {

namespace {
Status unknown_worker(uint64_t id) {
  return make_error(Code::NotFound, "unknown_worker", "no worker " + std::to_string(id) + "; register again");
}
// The result without its records (its splats: none, for a photon unit).
SplatResult without_records(const SplatResult& r) {
  SplatResult out;
  out.job_id = r.job_id;
  out.pass = r.pass;
  out.unit = r.unit;
  out.path_begin = r.path_begin;
  out.path_end = r.path_end;
  out.seconds = r.seconds;
  out.splats.reset(r.splats.window);
  out.splats.counters = r.splats.counters;
  out.splats.pixel = r.splats.pixel;
  out.splats.value = r.splats.value;
  return out;
}

}  // namespace

Status Coordinator::Impl::durable(uint64_t ticket) {
  try {
    commits.wait(ticket);
    return Status::success();
  } catch (const std::exception& e) {
    return internal_error(e);
  }
}

Status Coordinator::Impl::check_tile_result(const JobState& job, size_t unit, const TileResult& result) {
  if (!(result.film.rect() == job.rect(unit)) || result.sample_begin != job.sample_begin(unit) ||
      result.sample_end != job.sample_end(unit))
    return make_error(Code::BadRequest, "bad_result", "the result's rectangle or samples do not match the unit");
  if (job.is_done(unit)) return Status::success();  // (a late copy: a duplicate, compared with the first)
  if (result.film.has_aovs() != job.plan().settings.sums_aovs())
    return make_error(Code::BadRequest, "bad_result",
                      job.plan().settings.sums_aovs() ? "a result of a job with AOVs must carry the AOV sums (format version 4)"
                                                  : "the result carries AOV sums the job did not ask for");
  if (!job.result_fits(unit, result.film))
    return make_error(Code::BadRequest, "bad_result",
                      "the result's per-pixel sample counts are not those its adaptive pass gives the tile");
  if (job.tile_leaves_state(unit)) {
    std::string error;
    if (!check_sppm_state(result.tile_state, size_t(result.film.rect().area()), error))
      return make_error(Code::BadRequest, "bad_result", "the result's " + error);
  } else if (!result.tile_state.empty()) {
    return make_error(Code::BadRequest, "bad_result", "the result carries per-pixel state the job's passes do not use");
  }
  return Status::success();
}

Status Coordinator::Impl::check_splat_result(const JobState& job, size_t unit, const SplatResult& result) {
  if (!(result.splats.window == job.plan().window) || std::pair{result.path_begin, result.path_end} != job.paths(unit))
    return make_error(Code::BadRequest, "bad_result", "the result's window or light paths do not match the unit");
  return Status::success();
}

Status Coordinator::Impl::check_point_records(const UnitUpload& upload) {
  if (upload.records().empty()) return Status::success();
  std::optional<IntegratorType> type;
  {
    MutexLock lock(mu);
    if (const JobState* job = jobs.find(upload.job())) type = job->point_records();
  }
  // (Every record's values: megabytes of them, checked off the lock; check_result checks the rest.)
  std::string error;
  if (type && !tessera::check_point_records(*type, upload.records(), error))
    return make_error(Code::BadRequest, "bad_result", error);
  return Status::success();
}

Result<size_t> Coordinator::Impl::check_result(uint64_t worker, const UnitUpload& upload) {
  WorkerInfo* w = workers.find(worker);
  if (!w) return unknown_worker(worker);
  saw_worker(worker, *w);
  JobState* found = jobs.find(upload.job());
  if (!found) return unknown_job(upload.job());
  JobState& job = *found;
  if (job.phase() == JobPhase::Cancelled || job.phase() == JobPhase::Failed)
    return make_error(Code::Gone, "job_ended", "job " + std::to_string(job.id()) + " is " + phase_name(job.phase()));
  if (!job.has_unit(upload.index(), upload.pass()))
    return make_error(Code::BadRequest, "bad_result", "tile or pass out of range for job " + std::to_string(job.id()));
  const size_t unit = job.unit(upload.index(), upload.pass());
  if (job.is_tile_unit(unit) != bool(upload.tile))
    return make_error(Code::BadRequest, "bad_result",
                      job.is_tile_unit(unit) ? "a splat result for a unit of a tile" : "a tile result for a unit of light paths");
  if (Status st = upload.tile ? check_tile_result(job, unit, *upload.tile) : check_splat_result(job, unit, *upload.splats);
      !st.ok())
    return st;
  std::string error;
  if (!job.is_done(unit) && !job.check_training(unit, upload.records(), error))
    return make_error(Code::BadRequest, "bad_result", error);
  return unit;
}

void Coordinator::Impl::result_committed(bool durable, uint64_t job_id, size_t unit, uint64_t worker,
                                         const UnitUpload& upload, size_t bytes) {
  JobState* found = jobs.find(job_id);
  if (!found) return;
  JobState& job = *found;
  if (!durable) {  // not acknowledged: the unit is open again
    job.commit_failed(unit);
    work_cv.notify_all();
    return;
  }
  const uint64_t samples = job.unit_samples(unit);
  const bool added = upload.tile ? job.add_result(unit, std::move(upload.tile->film), worker, upload.records(),
                                                  std::move(upload.tile->tile_state))
                                 : job.add_splats(unit, std::move(upload.splats->splats), worker, upload.records());
  if (!added) return;  // (a retry rebuilt it meanwhile)
  job.unit_times.add(upload.seconds());
  save_decisions(job);
  if (upload.tile) checkpoint_tile(job, job.tile_of(unit), 1);
  fold_splats(job);
  job.result_bytes += bytes;
  ++metrics.counters.done;
  metrics.counters.bytes_in += bytes;
  if (WorkerInfo* w = workers.find(worker)) {
    w->units_done += 1;
    w->samples_done += samples;
    w->render_seconds += upload.seconds();
  }
  log_event(spdlog::level::debug, "lease.done",
            {{"job", job.id()}, {"unit", unit}, {"worker", worker}, {"seconds", upload.seconds()}});
  // (The phase is kept until durable; a crash before that finds the job complete at start-up.)
  if (!is_terminal(job.phase()) && job.complete()) complete_job(job);
}

uint64_t Coordinator::Impl::commit_result(JobState& job, size_t unit, uint64_t worker, const UnitUpload& upload,
                                          const std::shared_ptr<const UploadBytes>& bytes) {
  // The tile's next pass with all before it checkpointed: stored as the tile's new checkpoint (its
  // own bytes never stored). Otherwise stored as it came, and folded in later.
  std::shared_ptr<JobState::Checkpoint> cp;
  if (upload.tile)
    if (auto with = job.checkpoint_with(unit, upload.tile->film, upload.tile->tile_state))
      cp = std::make_shared<JobState::Checkpoint>(std::move(*with));
  job.start_commit(unit);
  // Another copy is still being rendered (speculative, or re-issued from a worker thought dead):
  // its result will be checked against this one.
  if (job.active_leases(unit) > 0) job.remember_digest(unit, upload.digest());
  return commits.append(
      [id = job.id(), index = upload.index(), pass = upload.pass(), worker, cp, upload, data = cp ? nullptr : bytes,
       now = wall_seconds()](Store& st) {
        const std::string& records = upload.records();
        // A photon unit (records, no splats) is stored without its records, which its training
        // rows hold until its map is stored: a pass's photons are not kept twice, nor for ever.
        const std::string stripped = upload.splats && upload.splats->splats.pixel.empty() && !records.empty()
                                         ? encode_splat_result(without_records(*upload.splats))
                                         : std::string();
        const std::string_view row = !stripped.empty() ? std::string_view(stripped) : data ? data->view() : std::string_view();
        (void)st.add_result(id, index, pass, worker, row, now);
        if (!records.empty()) st.save_training(id, index, pass, records);
        // (This pass's row is stored without its bytes and the earlier ones' were dropped: nothing
        // for the checkpoint to drop, hence `from` = `passes`.)
        if (cp) st.save_checkpoint(id, index, cp->passes, encode_checkpoint(id, *cp), {});
      },
      GroupCommit::Retry::No,
      [this, id = job.id(), unit, worker, upload, cp, n = bytes->view().size()](bool durable) TESSERA_REQUIRES(mu) {
        JobState* job = jobs.find(id);
        if (durable && cp && job) job->checkpoint_stored(cp->tile, cp->passes);
        result_committed(durable, id, unit, worker, upload, n);
      });
}

void Coordinator::Impl::fold_splats(JobState& job) {
  if (job.folding || !job.splats_ready()) return;
  job.folding = true;
  background.push([this, id = job.id()] {
    // About a tenth of a millisecond of adding per hold of the lock (a range of 65536 paths
    // splats a few hundred thousand times).
    constexpr size_t kChunk = size_t(1) << 14;
    for (;;) {
      MutexLock lock(mu);
      JobState* job = jobs.find(id);
      if (!job) return;
      (void)job->fold_splats(kChunk);
      if (job->splats_ready()) continue;  // (the lock is let go between chunks)
      job->folding = false;
      if (!is_terminal(job->phase()) && job->complete()) complete_job(*job);
      return;
    }
  });
}

void Coordinator::Impl::checkpoint_tile(JobState& job, uint32_t tile, uint32_t min_new) {
  std::optional<JobState::Checkpoint> cp = job.take_checkpoint(tile, min_new);
  if (!cp) return;
  auto shared = std::make_shared<JobState::Checkpoint>(std::move(*cp));
  (void)commits.append(
      [id = job.id(), shared, held = job.tile_passes(shared->from, shared->passes)](Store& st) {
        st.save_checkpoint(id, shared->tile, shared->passes, encode_checkpoint(id, *shared), held);
      },
      GroupCommit::Retry::No,
      [this, id = job.id(), tile = shared->tile, from = shared->from](bool durable) TESSERA_REQUIRES(mu) {
        JobState* job = jobs.find(id);
        if (!durable && job) job->checkpoint_failed(tile, from);
      });
}

void Coordinator::Impl::check_duplicate(JobState& job, size_t unit, uint64_t worker, const Sha256Digest& digest) {
  ++job.duplicates;
  ++metrics.counters.duplicates;
  const Sha256Digest* first = job.digest(unit);
  if (!first || *first == digest) return;
  // Renders are deterministic: a different answer for the same unit means a broken worker.
  ++job.mismatched;
  ++metrics.counters.mismatched;
  log_event(spdlog::level::err, "result.mismatch",
            {{"job", job.id()}, {"tile", job.tile_of(unit)}, {"pass", job.pass_of(unit)}, {"worker", worker}});
}

BodyLimit Coordinator::result_limit(uint64_t worker, uint64_t lease) {
  Impl& s = *impl_;
  {
    MutexLock lock(s.mu);
    const LeaseInfo* l = s.leases.find(lease);
    const JobState* job = l && l->worker == worker ? s.jobs.find(l->job) : nullptr;
    if (job && !job->is_tile_unit(l->unit)) {
      const auto [begin, end] = job->paths(l->unit);
      return {max_splat_result_bytes(end - begin, kMaxTrainingBytes, uint64_t(job->plan().window.area())),
              "a result of lease " + std::to_string(lease) + " (" + std::to_string(end - begin) + " light paths)"};
    }
    if (job) {
      const TileRect& r = job->rect(l->unit);
      const bool aovs = job->plan().settings.sums_aovs(), training = job->sequencer().pass(job->pass_of(l->unit)).feeds.has_value();
      return {max_tile_result_bytes(r, aovs, training, job->tile_leaves_state(l->unit)),
              "a result of lease " + std::to_string(lease) + " (a " + std::to_string(r.width()) + "x" +
                  std::to_string(r.height()) + " tile" + (aovs ? ", with AOV sums" : "") +
                  (training ? ", with training records" : "") + ")"};
    }
  }
  const int t = s.opt.limits.max_tile_size;
  return {max_tile_result_bytes({0, 0, t, t}, true, true, true),
          "a result of a lease this coordinator does not hold (as much as the largest unit: a " + std::to_string(t) +
              "x" + std::to_string(t) + " tile with AOV sums, training records and per-pixel state)"};
}

std::string Coordinator::spool_dir() const { return (std::filesystem::path(impl_->opt.data_dir) / "tmp").string(); }

Result<ResultAck> Coordinator::upload_result(uint64_t worker, uint64_t /*lease*/, std::shared_ptr<const UploadBytes> bytes,
                                             bool next) {
  Impl& s = *impl_;
  const auto t0 = Clock::now();
  Result<UnitUpload> decoded = decode_upload(bytes->view(), s.opt.limits.max_pixels);  // (off the lock)
  if (!decoded.ok()) return decoded.status;
  const UnitUpload& upload = decoded.value;
  if (Status st = s.check_point_records(upload); !st.ok()) return st;
  s.adopt_worker(worker);
  // Decided here and appended to the group commit; its callback adds it to the job once durable.
  ResultAck ack{/*accepted=*/true, /*duplicate=*/false, next, std::nullopt};
  uint64_t ticket = 0;
  std::optional<Impl::IssuedLease> issued;
  {
    MutexLock lock(s.mu);
    Result<size_t> checked = s.check_result(worker, upload);
    if (!checked.ok()) return checked.status;
    const size_t unit = checked.value;
    JobState& job = *s.jobs.find(upload.job());
    for (uint64_t id : s.leases.of_unit(job.id(), unit))
      if (s.leases.find(id)->worker == worker) s.end_lease(id);
    if (job.is_done(unit) && job.accepted_from(unit) == worker) {
      // The same worker again: a retry of an upload whose answer was lost (the coordinator
      // restarted, or the connection broke), not a second render. Answered as it was the first time.
    } else if (job.is_done(unit) || job.is_committing(unit)) {
      s.check_duplicate(job, unit, worker, upload.digest());
      ack.accepted = false;
      ack.duplicate = true;
    } else {
      ticket = s.commit_result(job, unit, worker, upload, bytes);
    }
    if (next) issued = s.next_lease(worker);  // (logged after the result: one commit for both)
  }
  if (Status st = ticket ? s.durable(ticket) : Status::success(); !st.ok()) {
    if (issued) {  // (its own batch may have committed: the worker will not get it, so it ends)
      MutexLock lock(s.mu);
      s.end_lease(issued->lease.id);
    }
    return st;
  }
  if (issued) {
    if (Status st = s.durable(issued->ticket); !st.ok()) return st;
    ack.next = std::move(issued->lease);
  }
  s.metrics.upload_seconds.observe(std::chrono::duration<double>(Clock::now() - t0).count());
  return ack;
}

Status Coordinator::fail_lease(uint64_t worker, uint64_t lease, const std::string& error) {
  Impl& s = *impl_;
  const std::string reason = error.substr(0, 2000);
  MutexLock lock(s.mu);
  const LeaseInfo* l = s.leases.find(lease);
  if (!l || l->worker != worker)
    return make_error(Code::NotFound, "unknown_lease",
                      "worker " + std::to_string(worker) + " holds no lease " + std::to_string(lease));
  JobState* found = s.jobs.find(l->job);
  s.end_lease(lease);
  if (!found) return Status::success();
  JobState& job = *found;
  ++job.failures_by_worker[worker];
  ++s.metrics.counters.failed;
  job.last_failure = reason;
  log_event(spdlog::level::warn, "lease.failed", {{"lease", lease}, {"job", job.id()}, {"worker", worker}, {"reason", reason}});
  // The job fails when its work fails on several workers (or on every worker there is).
  const size_t needed = std::max<size_t>(1, std::min<size_t>(size_t(s.opt.failed_workers_limit), s.workers.live()));
  if (is_terminal(job.phase()) || job.failures_by_worker.size() < needed) return Status::success();
  const uint64_t ticket = s.change_phase(job, JobPhase::Failed,
                                         "failed on " + std::to_string(job.failures_by_worker.size()) +
                                             " worker(s); last error: " + reason);
  lock.unlock();
  return s.durable(ticket);
}

}  // namespace tessera::server
