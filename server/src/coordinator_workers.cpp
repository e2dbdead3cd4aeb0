// Workers and leases: registration (with the build check), long-poll leasing, heartbeats, results,
// failures and sign-off.
#include "coordinator_impl.h"
#include "event_log.h"

#include "tessera/farm/sha256.h"
#include "tessera/farm/tile_result.h"

#include <limits>

#include <spdlog/spdlog.h>

namespace tessera::server {

using nlohmann::json;

namespace {
Status unknown_worker(uint64_t id) {
  return make_error(Code::NotFound, "unknown_worker", "no worker " + std::to_string(id) + "; register again");
}
}  // namespace

void Coordinator::Impl::set_worker_state(uint64_t id, WorkerInfo& w, WorkerState to) {
  if (w.state == to || w.state == WorkerState::Gone) return;  // (signing off is final)
  const WorkerState from = w.state;
  w.state = to;
  if (to == WorkerState::Lost) {
    log_event(spdlog::level::warn, "worker.lost", {{"worker", id}, {"name", w.row.name}});
    // Dead: what it held is re-issued now rather than after each lease's own expiry.
    end_leases_if([&](const LeaseInfo& l) { return l.worker == id; });
  } else if (from == WorkerState::Lost) {
    log_event(spdlog::level::info, "worker.back", {{"worker", id}, {"name", w.row.name}});
  }
}

void Coordinator::Impl::saw_worker(uint64_t id, WorkerInfo& w) {
  w.last_seen = Clock::now();
  if (w.state == WorkerState::Lost) update_busy(id, w);
}

void Coordinator::Impl::update_busy(uint64_t id, WorkerInfo& w) {
  if (w.state == WorkerState::Draining || w.state == WorkerState::Gone) return;
  set_worker_state(id, w, leases_held.contains(id) ? WorkerState::Busy : WorkerState::Idle);
}

WorkerInfo* Coordinator::Impl::find_worker(uint64_t id) {
  auto it = workers.find(id);
  return it == workers.end() ? nullptr : &it->second;
}

void Coordinator::Impl::adopt_worker(uint64_t id) {
  if (id == 0 || id > workers_before_start) return;  // (registered with this process, or never)
  {
    std::lock_guard<std::mutex> lock(mu);
    if (workers.contains(id)) return;
  }
  std::optional<WorkerRow> row = store.worker(id);
  if (!row) return;
  std::lock_guard<std::mutex> lock(mu);
  auto [it, added] = workers.try_emplace(id);
  if (!added) return;
  it->second.row = std::move(*row);
  it->second.last_seen = Clock::now();
}

Result<Registration> Coordinator::register_worker(const WorkerHello& hello) {
  Impl& s = *impl_;
  std::string mismatch =
      fingerprint_mismatch(s.fingerprint, BuildFingerprint{hello.version, hello.isa, hello.probe});
  if (!mismatch.empty()) {
    log_event(spdlog::level::warn, "worker.refused", {{"name", hello.name}, {"reason", mismatch}});
    return make_error(Code::Conflict, "incompatible_worker", mismatch);
  }
  try {
    WorkerRow row{0, hello.name, hello.version, hello.isa, hello.threads, hello.memory_bytes, wall_seconds()};
    row.id = s.store.add_worker(row);  // (durable before the id is handed out; not under `mu`)
    std::lock_guard<std::mutex> lock(s.mu);
    WorkerInfo& w = s.workers[row.id];
    w.row = row;
    w.last_seen = Clock::now();
    log_event(spdlog::level::info, "worker.registered",
              {{"worker", row.id}, {"name", hello.name}, {"threads", hello.threads}, {"isa", hello.isa}});
    return Registration{row.id, s.opt.heartbeat_interval * kMissedHeartbeats, s.opt.heartbeat_interval,
                        s.opt.max_poll_wait};
  } catch (const std::exception& e) {
    return internal_error(e);
  }
}

std::optional<UnitChoice> Coordinator::Impl::choose_unit_for(uint64_t worker) {
  auto excluded = [&](const JobState& job) {
    auto f = job.failures_by_worker.find(worker);
    return f != job.failures_by_worker.end() && f->second >= opt.worker_failure_limit;
  };
  std::vector<JobCandidate> candidates;
  int top = std::numeric_limits<int>::min();
  for (auto& [id, job] : jobs) {
    if (is_terminal(job->phase)) continue;
    candidates.push_back({id, job->priority(), job->next_unit(), excluded(*job)});
    top = std::max(top, job->priority());
  }
  std::vector<LeaseCandidate> outstanding;
  // Leases are listed only when a job outranks the fresh choice (rare: a job's last units).
  if (opt.speculate && speculation_floor(candidates) < top) {
    for (auto& [id, l] : leases) {
      auto job = jobs.find(l.job);
      if (job == jobs.end() || is_terminal(job->second->phase)) continue;
      outstanding.push_back({l.job, job->second->priority(), l.unit, l.worker,
                             job->second->active_leases(l.unit), excluded(*job->second)});
    }
  }
  return choose_unit(candidates, outstanding, worker, opt.speculate);
}

Coordinator::Impl::IssuedLease Coordinator::Impl::issue_lease(uint64_t worker, WorkerInfo& w,
                                                              const UnitChoice& choice) {
  JobState& job = *jobs.at(choice.job);
  const size_t unit = choice.unit;
  const double now = wall_seconds();
  IssuedLease issued;
  // The job's first lease: its phase is logged ahead of the lease.
  if (job.phase == JobPhase::Queued) (void)change_phase(job, JobPhase::Running);
  Lease l;
  l.id = ++last_lease_id;
  l.job_id = job.id();
  l.tile = job.tile_of(unit);
  l.pass = job.pass_of(unit);
  l.rect = job.rect(unit);
  l.sample_begin = job.sample_begin(unit);
  l.sample_end = job.sample_end(unit);
  if (std::optional<PassSamples> samples = job.lease_samples(unit)) l.samples = std::move(*samples);
  l.guide = job.lease_guide(unit);
  l.seconds_to_expiry = opt.heartbeat_interval * kMissedHeartbeats;
  l.settings = job.plan().settings;
  l.scene_file = job.plan().scene_file;
  l.files = job.plan().files;
  issued.ticket = commits.append(
      [=, id = l.id, job_id = l.job_id, tile = l.tile, pass = l.pass](Store& st) {
        st.log_lease(id, job_id, tile, pass, worker, now);
      },
      GroupCommit::Retry::No,
      [this, id = l.id](bool durable) {
        if (!durable) end_lease_id(id);  // not logged: never handed out
      });
  job.lease_started(unit);
  add_lease(LeaseInfo{l.id, l.job_id, worker, unit, Clock::now() + dead_after()});
  set_worker_state(worker, w, WorkerState::Busy);
  if (job.lease_job_part_bytes == 0) job.lease_job_part_bytes = lease_job_part_bytes(l);
  const size_t bytes = lease_json_bytes(l, job.lease_job_part_bytes);
  job.lease_bytes += bytes;
  counters.bytes_out += bytes;
  ++counters.leased;
  if (choice.speculative) ++counters.speculative;
  log_event(spdlog::level::debug, "lease.issued",
            {{"lease", l.id}, {"job", l.job_id}, {"tile", l.tile}, {"pass", l.pass}, {"worker", worker},
             {"speculative", choice.speculative}});
  issued.lease = std::move(l);
  return issued;
}

Result<std::optional<Lease>> Coordinator::lease(uint64_t worker, double wait_seconds) {
  Impl& s = *impl_;
  // Bounded: beyond this many waiting polls the answer is "nothing now" at once, so waiting
  // workers can never occupy every HTTP thread.
  // The slot is taken atomically, so concurrent polls cannot all pass the check at once.
  struct PollSlot {
    std::atomic<int>& n;
    ~PollSlot() { --n; }
  } slot{s.waiting_polls};
  if (s.waiting_polls.fetch_add(1) >= s.opt.max_waiting_polls || !(wait_seconds >= 0)) wait_seconds = 0;  // NaN too
  const auto t0 = Clock::now();
  s.adopt_worker(worker);
  std::unique_lock<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  s.saw_worker(worker, *w);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                           std::clamp(wait_seconds, 0.0, s.opt.max_poll_wait)));
  for (;;) {
    if (s.stopping) return make_error(Code::Unavailable, "stopping", "the coordinator is shutting down");
    if (w->state == WorkerState::Draining)
      return make_error(Code::Gone, "drained", "worker " + std::to_string(worker) + " is being drained: no more work");
    if (std::optional<UnitChoice> choice = s.choose_unit_for(worker)) {
      Impl::IssuedLease issued = s.issue_lease(worker, *w, *choice);
      lock.unlock();
      if (Status st = s.durable(issued.ticket); !st.ok()) return st;  // (its callback ended it)
      s.lease_wait.observe(std::chrono::duration<double>(Clock::now() - t0).count());
      return std::optional<Lease>(std::move(issued.lease));
    }
    if (Clock::now() >= deadline) break;
    s.update_busy(worker, *w);  // waiting for work with none in hand: idle, as the dashboard shows
    s.work_cv.wait_until(lock, deadline);
    s.saw_worker(worker, *w);  // (a long poll is a sign of life too)
  }
  s.update_busy(worker, *w);
  s.lease_wait.observe(std::chrono::duration<double>(Clock::now() - t0).count());
  return std::optional<Lease>();
}

Result<std::vector<uint64_t>> Coordinator::heartbeat(uint64_t worker, const Heartbeat& heartbeat) {
  Impl& s = *impl_;
  s.adopt_worker(worker);
  std::lock_guard<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  s.saw_worker(worker, *w);
  if (heartbeat.memory) w->memory = *heartbeat.memory;
  std::vector<uint64_t> drop;
  for (const HeldLease& l : heartbeat.leases)
    if (!s.keep_lease(worker, l)) drop.push_back(l.id);
  s.update_busy(worker, *w);
  return drop;
}

bool Coordinator::Impl::keep_lease(uint64_t worker, const HeldLease& held) {
  auto it = leases.find(held.id);
  if (it != leases.end() && it->second.worker == worker) {
    auto job = jobs.find(it->second.job);
    if (job != jobs.end() && job->second->is_done(it->second.unit)) {
      end_lease(it);  // someone else delivered it first
      return false;
    }
    it->second.expires = Clock::now() + dead_after();
    return true;
  }
  // Unknown (ended while its worker was thought dead, or logged by a process before a restart
  // that did not hold it): kept if its work is still wanted.
  auto job = jobs.find(held.job);
  if (job == jobs.end() || is_terminal(job->second->phase) || held.tile >= job->second->num_tiles() ||
      held.pass >= job->second->num_passes())
    return false;
  const size_t unit = job->second->unit(held.tile, held.pass);
  if (job->second->is_done(unit)) return false;
  if (it != leases.end()) end_lease(it);  // (an id another worker holds: never two owners)
  job->second->lease_started(unit);
  add_lease(LeaseInfo{held.id, held.job, worker, unit, Clock::now() + dead_after()});
  return true;
}

Result<size_t> Coordinator::Impl::check_result(uint64_t worker, const TileResult& result) {
  WorkerInfo* w = find_worker(worker);
  if (!w) return unknown_worker(worker);
  saw_worker(worker, *w);
  auto it = jobs.find(result.job_id);
  if (it == jobs.end()) return unknown_job(result.job_id);
  JobState& job = *it->second;
  if (job.phase == JobPhase::Cancelled || job.phase == JobPhase::Failed)
    return make_error(Code::Gone, "job_ended", "job " + std::to_string(job.id()) + " is " + phase_name(job.phase));
  if (result.tile >= job.num_tiles() || result.pass >= job.num_passes())
    return make_error(Code::BadRequest, "bad_result", "tile or pass out of range for job " + std::to_string(job.id()));
  const size_t unit = job.unit(result.tile, result.pass);
  if (!(result.film.rect() == job.rect(unit)) || result.sample_begin != job.sample_begin(unit) ||
      result.sample_end != job.sample_end(unit))
    return make_error(Code::BadRequest, "bad_result", "the result's rectangle or samples do not match the unit");
  // (A late copy of a done unit is answered as a duplicate, its sums compared with the accepted ones.)
  if (!job.is_done(unit) && result.film.has_aovs() != job.plan().settings.denoise)
    return make_error(Code::BadRequest, "bad_result",
                      job.plan().settings.denoise ? "a result of a denoised job must carry the AOV sums (format version 4)"
                                                  : "the result carries AOV sums the job did not ask for");
  if (!job.is_done(unit) && !job.result_fits(unit, result.film))
    return make_error(Code::BadRequest, "bad_result",
                      "the result's per-pixel sample counts are not those its adaptive pass gives the tile");
  std::string error;
  if (!job.is_done(unit) && !job.check_training(unit, result.training, error))
    return make_error(Code::BadRequest, "bad_result", error);
  return unit;
}

void Coordinator::Impl::result_committed(bool durable, uint64_t job_id, size_t unit, uint64_t worker,
                                         TileResult& result, size_t bytes) {
  auto it = jobs.find(job_id);
  if (it == jobs.end()) return;
  JobState& job = *it->second;
  if (!durable) {  // not acknowledged: the unit is open again
    job.commit_failed(unit);
    work_cv.notify_all();
    return;
  }
  const uint64_t samples = job.unit_samples(unit);
  if (!job.add_result(unit, std::move(result.film), worker, result.training)) return;  // (a retry rebuilt it meanwhile)
  save_decisions(job);
  checkpoint_tile(job, job.tile_of(unit), 1);
  job.result_bytes += bytes;
  ++counters.done;
  counters.bytes_in += bytes;
  if (WorkerInfo* w = find_worker(worker)) {
    w->units_done += 1;
    w->samples_done += samples;
    w->render_seconds += result.seconds;
  }
  log_event(spdlog::level::debug, "lease.done",
            {{"job", job.id()}, {"unit", unit}, {"worker", worker}, {"seconds", result.seconds}});
  // (The phase is kept until durable; a crash before that finds the job complete at start-up.)
  if (!is_terminal(job.phase) && job.complete()) complete_job(job);
}

uint64_t Coordinator::Impl::commit_result(JobState& job, size_t unit, uint64_t worker,
                                          const std::shared_ptr<TileResult>& result, std::string_view bytes) {
  // The tile's next pass with all before it checkpointed: stored as the tile's new checkpoint (its
  // own bytes never stored). Otherwise stored as it came, and folded in later.
  std::shared_ptr<JobState::Checkpoint> cp;
  if (auto with = job.checkpoint_with(unit, result->film)) cp = std::make_shared<JobState::Checkpoint>(std::move(*with));
  job.start_commit(unit);
  // Another copy is still being rendered (speculative, or re-issued from a worker thought dead):
  // its result will be checked against this one.
  if (job.active_leases(unit) > 0) job.remember_digest(unit, tile_digest(result->film));
  return commits.append(
      [id = job.id(), tile = result->tile, pass = result->pass, worker, cp, result, data = cp ? "" : std::string(bytes),
       now = wall_seconds()](Store& st) {
        (void)st.add_result(id, tile, pass, worker, data, now);
        if (!result->training.empty()) st.save_training(id, tile, pass, result->training);
        // (This pass's row is stored without its bytes and the earlier ones' were dropped: nothing
        // for the checkpoint to drop, hence `from` = `passes`.)
        if (cp) st.save_checkpoint(id, tile, cp->passes, cp->passes, encode_checkpoint(id, *cp));
      },
      GroupCommit::Retry::No,
      [this, id = job.id(), unit, worker, result, cp, n = bytes.size()](bool durable) {
        auto it = jobs.find(id);
        if (durable && cp && it != jobs.end()) it->second->checkpoint_stored(cp->tile, cp->passes);
        result_committed(durable, id, unit, worker, *result, n);
      });
}

std::optional<Coordinator::Impl::IssuedLease> Coordinator::Impl::next_lease(uint64_t worker) {
  WorkerInfo* w = find_worker(worker);
  if (stopping || !w || w->state == WorkerState::Draining) return std::nullopt;
  std::optional<UnitChoice> choice = choose_unit_for(worker);
  if (!choice) return std::nullopt;
  return issue_lease(worker, *w, *choice);
}

Result<ResultAck> Coordinator::upload_result(uint64_t worker, uint64_t /*lease*/, std::string_view bytes, bool next) {
  Impl& s = *impl_;
  const auto t0 = Clock::now();
  auto result = std::make_shared<TileResult>();
  std::string error;
  if (!decode_tile_result(bytes, *result, error, s.opt.limits.max_pixels))
    return make_error(Code::BadRequest, "bad_result", error);
  s.adopt_worker(worker);
  // Decided here and appended to the group commit; its callback adds it to the job once durable.
  ResultAck ack{/*accepted=*/true, /*duplicate=*/false, next, std::nullopt};
  uint64_t ticket = 0;
  std::optional<Impl::IssuedLease> issued;
  {
    std::lock_guard<std::mutex> lock(s.mu);
    Result<size_t> checked = s.check_result(worker, *result);
    if (!checked.ok()) return checked.status;
    const size_t unit = checked.value;
    JobState& job = *s.jobs.at(result->job_id);
    s.end_leases_if([&](const LeaseInfo& l) { return l.job == job.id() && l.unit == unit && l.worker == worker; });
    if (job.is_done(unit) && job.accepted_from(unit) == worker) {
      // The same worker again: a retry of an upload whose answer was lost (the coordinator
      // restarted, or the connection broke), not a second render. Answered as it was the first time.
    } else if (job.is_done(unit) || job.is_committing(unit)) {
      s.check_duplicate(job, unit, worker, result->film);
      ack.accepted = false;
      ack.duplicate = true;
    } else {
      ticket = s.commit_result(job, unit, worker, result, bytes);
    }
    if (next) issued = s.next_lease(worker);  // (logged after the result: one commit for both)
  }
  if (Status st = ticket ? s.durable(ticket) : Status::success(); !st.ok()) {
    if (issued) {  // (its own batch may have committed: the worker will not get it, so it ends)
      std::lock_guard<std::mutex> lock(s.mu);
      s.end_lease_id(issued->lease.id);
    }
    return st;
  }
  if (issued) {
    if (Status st = s.durable(issued->ticket); !st.ok()) return st;
    ack.next = std::move(issued->lease);
  }
  s.upload_seconds.observe(std::chrono::duration<double>(Clock::now() - t0).count());
  return ack;
}

void Coordinator::Impl::check_duplicate(JobState& job, size_t unit, uint64_t worker, const FilmTile& film) {
  ++job.duplicates;
  ++counters.duplicates;
  const Sha256Digest* first = job.digest(unit);
  if (!first || *first == tile_digest(film)) return;
  // Renders are deterministic: a different answer for the same unit means a broken worker.
  ++job.mismatched;
  ++counters.mismatched;
  log_event(spdlog::level::err, "result.mismatch",
            {{"job", job.id()}, {"tile", job.tile_of(unit)}, {"pass", job.pass_of(unit)}, {"worker", worker}});
}

Status Coordinator::fail_lease(uint64_t worker, uint64_t lease, const std::string& error) {
  Impl& s = *impl_;
  const std::string reason = error.substr(0, 2000);
  std::unique_lock<std::mutex> lock(s.mu);
  auto it = s.leases.find(lease);
  if (it == s.leases.end() || it->second.worker != worker)
    return make_error(Code::NotFound, "unknown_lease", "worker " + std::to_string(worker) + " holds no lease " +
                                                           std::to_string(lease));
  auto job_it = s.jobs.find(it->second.job);
  s.end_lease(it);
  if (job_it == s.jobs.end()) return Status::success();
  JobState& job = *job_it->second;
  ++job.failures_by_worker[worker];
  ++s.counters.failed;
  job.last_failure = reason;
  log_event(spdlog::level::warn, "lease.failed", {{"lease", lease}, {"job", job.id()}, {"worker", worker}, {"reason", reason}});
  // The job fails when its work fails on several workers (or on every worker there is).
  size_t live = 0;
  for (auto& [id, w] : s.workers) live += is_live(w.state);
  const size_t needed = std::max<size_t>(1, std::min<size_t>(size_t(s.opt.failed_workers_limit), live));
  if (is_terminal(job.phase) || job.failures_by_worker.size() < needed) return Status::success();
  const uint64_t ticket = s.change_phase(job, JobPhase::Failed,
                                         "failed on " + std::to_string(job.failures_by_worker.size()) +
                                             " worker(s); last error: " + reason);
  lock.unlock();
  return s.durable(ticket);
}

Status Coordinator::sign_off(uint64_t worker) {
  Impl& s = *impl_;
  s.adopt_worker(worker);
  uint64_t ticket = 0;
  {
    std::lock_guard<std::mutex> lock(s.mu);
    WorkerInfo* w = s.find_worker(worker);
    if (!w) return unknown_worker(worker);
    s.end_leases_if([&](const LeaseInfo& l) { return l.worker == worker; });
    s.set_worker_state(worker, *w, WorkerState::Gone);
    ticket = s.commits.append([worker, now = wall_seconds()](Store& st) { st.touch_worker(worker, now, "gone"); },
                              GroupCommit::Retry::UntilDurable);
    log_event(spdlog::level::info, "worker.signed_off", {{"worker", worker}});
  }
  return s.durable(ticket);
}

Status Coordinator::drain_worker(uint64_t worker) {
  Impl& s = *impl_;
  s.adopt_worker(worker);
  std::lock_guard<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  if (w->state == WorkerState::Gone)
    return make_error(Code::Conflict, "worker_gone", "worker " + std::to_string(worker) + " signed off");
  s.set_worker_state(worker, *w, WorkerState::Draining);
  s.work_cv.notify_all();  // its waiting polls return now
  log_event(spdlog::level::info, "worker.draining", {{"worker", worker}});
  return Status::success();
}

Result<std::vector<WorkerStatus>> Coordinator::list_workers() {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mu);
  std::vector<WorkerStatus> list;
  for (auto& [id, w] : s.workers)
    list.push_back({id, w.row.name, worker_state_name(w.state), int(w.row.threads), w.units_done, w.samples_done,
                    w.render_seconds > 0 ? double(w.samples_done) / w.render_seconds : 0.0, w.memory.scene_bytes,
                    w.memory.scenes, w.row.memory});
  return list;
}

}  // namespace tessera::server
