// Leases: which unit a worker gets (the scheduler's choice over the job registry's order), the
// long poll, heartbeats that keep leases alive, expiry, and the leases a restart inherits.
#include "coordinator_impl.h"
#include "event_log.h"
#include "tessera/core/check.h"

#include <spdlog/spdlog.h>

#include <algorithm>

namespace tessera::server {

namespace {
Status unknown_worker(uint64_t id) {
  return make_error(Code::NotFound, "unknown_worker", "no worker " + std::to_string(id) + "; register again");
}
}  // namespace

void Coordinator::Impl::add_lease(const LeaseInfo& lease) {
  if (leases.find(lease.id)) end_lease(lease.id);  // (an id another worker held: never two owners)
  leases.add(lease);
  if (JobState* job = jobs.find(lease.job)) job->lease_started(lease.unit);
}

void Coordinator::Impl::end_lease(uint64_t id) {
  std::optional<LeaseInfo> ended = leases.end(id);
  if (!ended) return;
  if (JobState* job = jobs.find(ended->job)) job->lease_ended(ended->unit);
  work_cv.notify_all();
}

std::optional<UnitChoice> Coordinator::Impl::choose_unit_for(uint64_t worker) {
  auto excluded = [&](const JobState& job) {
    auto f = job.failures_by_worker.find(worker);
    return f != job.failures_by_worker.end() && f->second >= opt.worker_failure_limit;
  };
  const std::vector<JobCandidate> candidates = jobs.candidates(excluded);
  // Only a worker holding no lease is idle enough for a copy of another's.
  const bool speculate = opt.speculate && !leases.holds(worker);
  std::vector<LeaseCandidate> outstanding;
  // Leases are listed only when a job outranks the fresh choice (rare: a job's last units), and
  // only those of the jobs that do.
  const int floor = speculation_floor(candidates);
  if (speculate && !candidates.empty() && floor < candidates.front().priority) {
    const Clock::time_point now = Clock::now();
    std::vector<std::pair<uint64_t, LeaseCandidate>> by_age;
    for (const JobCandidate& c : candidates) {
      if (c.priority <= floor) break;
      const JobState& job = *jobs.find(c.job);
      const std::optional<Clock::duration> after = speculation_threshold(job);
      for (uint64_t id : leases.job_leases(c.job)) {
        const LeaseInfo& l = *leases.find(id);
        LeaseCandidate lc{l.job, c.priority, l.unit, l.worker, job.active_leases(l.unit), c.excluded};
        lc.finished = job.unit_finished(l.unit);
        lc.overdue = after && now - l.issued > *after;
        by_age.push_back({id, lc});
      }
    }
    std::sort(by_age.begin(), by_age.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [id, l] : by_age) outstanding.push_back(l);
  }
  return choose_unit(candidates, outstanding, worker, speculate);
}

std::optional<Clock::duration> Coordinator::Impl::speculation_threshold(const JobState& job) const {
  if (opt.speculate_after == 0) return Clock::duration::zero();
  const std::optional<double> median = job.unit_times.median();
  if (!median) return std::nullopt;  // (no unit in yet: nothing to call late)
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(opt.speculate_after * *median));
}

Coordinator::Impl::IssuedLease Coordinator::Impl::issue_lease(uint64_t worker, WorkerInfo& w,
                                                              const UnitChoice& choice) {
  JobState& job = *jobs.find(choice.job);
  const size_t unit = choice.unit;
  TESSERA_CHECK(!job.unit_finished(unit));  // (an accepted unit is never leased again)
  const double now = wall_seconds();
  IssuedLease issued;
  // The job's first lease: its phase is logged ahead of the lease.
  if (job.phase() == JobPhase::Queued) (void)change_phase(job, JobPhase::Running);
  Lease l;
  l.id = leases.next_id();
  l.job_id = job.id();
  l.tile = job.tile_of(unit);
  l.pass = job.pass_of(unit);
  l.rect = job.rect(unit);
  l.sample_begin = job.sample_begin(unit);
  l.sample_end = job.sample_end(unit);
  if (std::optional<PassSamples> samples = job.lease_samples(unit)) l.samples = std::move(*samples);
  if (!job.is_tile_unit(unit)) l.paths = job.paths(unit);
  l.guide = job.lease_guide(unit);
  if (const std::string* state = job.lease_tile_state(unit)) l.tile_state = *state;
  l.seconds_to_expiry = opt.heartbeat_interval * kMissedHeartbeats;
  l.settings = job.plan().settings;
  l.scene_file = job.plan().scene_file;
  l.files = job.plan().files;
  issued.ticket = commits.append(
      [=, id = l.id, job_id = l.job_id, tile = l.tile, pass = l.pass](Store& st) {
        st.log_lease(id, job_id, tile, pass, worker, now);
      },
      GroupCommit::Retry::No,
      [this, id = l.id](bool durable) TESSERA_REQUIRES(mu) {
        if (!durable) end_lease(id);  // not logged: never handed out
      });
  const Clock::time_point issued_at = Clock::now();
  add_lease(LeaseInfo{l.id, l.job_id, worker, unit, issued_at + dead_after(), issued_at});
  set_worker_state(worker, w, WorkerState::Busy);
  if (job.lease_job_part_bytes == 0) job.lease_job_part_bytes = lease_job_part_bytes(l);
  const size_t bytes = lease_json_bytes(l, job.lease_job_part_bytes);
  job.lease_bytes += bytes;
  metrics.counters.bytes_out += bytes;
  ++metrics.counters.leased;
  job.lease_issued(unit);
  metrics.note_leases_per_unit(job.max_leases_per_unit());
  if (choice.speculative) ++metrics.counters.speculative;
  log_event(spdlog::level::debug, "lease.issued",
            {{"lease", l.id}, {"job", l.job_id}, {"tile", l.tile}, {"pass", l.pass}, {"worker", worker},
             {"speculative", choice.speculative}});
  issued.lease = std::move(l);
  return issued;
}

std::optional<Coordinator::Impl::IssuedLease> Coordinator::Impl::next_lease(uint64_t worker) {
  WorkerInfo* w = workers.find(worker);
  if (stopping || !w || w->state == WorkerState::Draining) return std::nullopt;
  std::optional<UnitChoice> choice = choose_unit_for(worker);
  if (!choice) return std::nullopt;
  return issue_lease(worker, *w, *choice);
}

Result<std::optional<Lease>> Coordinator::lease(uint64_t worker, double wait_seconds) {
  Impl& s = *impl_;
  // Bounded: beyond this many waiting polls the answer is "nothing now" at once, so waiting
  // workers can never occupy every HTTP thread. The slot is taken atomically, so concurrent polls
  // cannot all pass the check at once.
  struct PollSlot {
    std::atomic<int>& n;
    ~PollSlot() { --n; }
  } slot{s.waiting_polls};
  if (s.waiting_polls.fetch_add(1) >= s.opt.max_waiting_polls || !(wait_seconds >= 0)) wait_seconds = 0;  // NaN too
  const auto t0 = Clock::now();
  s.adopt_worker(worker);
  MutexLock lock(s.mu);
  WorkerInfo* w = s.workers.find(worker);
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
      s.metrics.lease_wait.observe(std::chrono::duration<double>(Clock::now() - t0).count());
      return std::optional<Lease>(std::move(issued.lease));
    }
    if (Clock::now() >= deadline) break;
    s.update_busy(worker, *w);  // waiting for work with none in hand: idle, as the dashboard shows
    s.work_cv.wait_until(lock, deadline);
    s.saw_worker(worker, *w);  // (a long poll is a sign of life too)
  }
  s.update_busy(worker, *w);
  s.metrics.lease_wait.observe(std::chrono::duration<double>(Clock::now() - t0).count());
  return std::optional<Lease>();
}

Result<std::vector<uint64_t>> Coordinator::heartbeat(uint64_t worker, const Heartbeat& heartbeat) {
  Impl& s = *impl_;
  s.adopt_worker(worker);
  MutexLock lock(s.mu);
  WorkerInfo* w = s.workers.find(worker);
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
  const LeaseInfo* known = leases.find(held.id);
  if (known && known->worker == worker) {
    const JobState* job = jobs.find(known->job);
    if (job && job->is_done(known->unit)) {
      end_lease(held.id);  // someone else delivered it first
      return false;
    }
    leases.extend(held.id, Clock::now() + dead_after());
    return true;
  }
  // Unknown (ended while its worker was thought dead, or logged by a process before a restart
  // that did not hold it): kept if its work is still wanted.
  const JobState* job = jobs.find(held.job);
  if (!job || is_terminal(job->phase()) || !job->has_unit(held.tile, held.pass)) return false;
  const size_t unit = job->unit(held.tile, held.pass);
  if (job->is_done(unit)) return false;
  const Clock::time_point now = Clock::now();
  add_lease(LeaseInfo{held.id, held.job, worker, unit, now + dead_after(), now});
  return true;
}

void Coordinator::Impl::hold_open_leases(JobState& job) {
  // Their workers may still be rendering them: a heartbeat naming the lease re-adopts it, and only
  // a unit nobody claims within dead_after() is leased again (never rendered twice for a restart).
  const Clock::time_point now = Clock::now();
  for (const LeaseRow& l : store.open_leases(job.id())) {
    if (!job.has_unit(l.tile, l.pass)) continue;
    const size_t unit = job.unit(l.tile, l.pass);
    if (job.is_done(unit)) continue;
    add_lease(LeaseInfo{l.id, job.id(), l.worker, unit, now + dead_after(), now});
  }
}

void Coordinator::Impl::reap_leases_and_workers() {
  std::vector<ReapWorker> live;
  for (const auto& [id, w] : workers.all()) live.push_back({id, is_live(w.state), w.last_seen});
  std::vector<ReapLease> held;
  held.reserve(leases.size());
  for (const auto& [id, l] : leases.all()) held.push_back({id, l.worker, l.expires});
  const Reaping reaping = decide_reaping(live, held, Clock::now(), dead_after());
  metrics.counters.expired += reaping.leases_of_lost;
  for (uint64_t id : reaping.lost_workers) set_worker_state(id, *workers.find(id), WorkerState::Lost);
  for (uint64_t id : reaping.expired_leases) {
    const LeaseInfo* l = leases.find(id);
    if (!l) continue;
    log_event(spdlog::level::warn, "lease.expired", {{"lease", l->id}, {"job", l->job}, {"unit", l->unit}, {"worker", l->worker}});
    ++metrics.counters.expired;
    end_lease(id);
  }
}

void Coordinator::Impl::reap_loop() {
  MutexLock lock(mu);
  auto next_retention = Clock::now();  // a pass at start-up, then every maintenance_interval (retention.h)
  while (!stopping) {
    work_cv.wait_for(lock, std::chrono::milliseconds(250));
    if (opt.maintenance_interval > 0 && Clock::now() >= next_retention && !stopping) {
      lock.unlock();
      try {
        (void)run_retention(wall_seconds());
      } catch (const std::exception& e) {
        spdlog::warn("retention pass failed: {}", e.what());
      }
      lock.lock();
      next_retention = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                          std::chrono::duration<double>(opt.maintenance_interval));
    }
    reap_leases_and_workers();
  }
}

}  // namespace tessera::server
