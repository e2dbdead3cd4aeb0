// Workers and leases: registration (with the build check), long-poll leasing, heartbeats, results,
// failures and sign-off.
#include "coordinator_impl.h"
#include "event_log.h"

#include "tessera/farm/tile_result.h"

#include <spdlog/spdlog.h>

namespace tessera::server {

using nlohmann::json;

namespace {
Status unknown_worker(uint64_t id) {
  return make_error(Code::NotFound, "unknown_worker", "no worker " + std::to_string(id) + "; register again");
}
}  // namespace

WorkerInfo* Coordinator::Impl::find_worker(uint64_t id) {
  auto it = workers.find(id);
  if (it != workers.end()) return &it->second;
  // After a restart: a worker registered with the previous process keeps its id.
  std::optional<WorkerRow> row = store.worker(id);
  if (!row) return nullptr;
  WorkerInfo& w = workers[id];
  w.row = *row;
  w.last_seen = Clock::now();
  return &w;
}

Result<json> Coordinator::register_worker(const json& body) {
  Impl& s = *impl_;
  WorkerHello hello;
  std::string error;
  if (!worker_hello_from_json(body, hello, error)) return make_error(Code::BadRequest, "bad_registration", error);
  std::string mismatch =
      fingerprint_mismatch(s.fingerprint, BuildFingerprint{hello.version, hello.isa, hello.probe});
  if (!mismatch.empty()) {
    log_event(spdlog::level::warn, "worker.refused", {{"name", hello.name}, {"reason", mismatch}});
    return make_error(Code::Conflict, "incompatible_worker", mismatch);
  }
  std::lock_guard<std::mutex> lock(s.mu);
  try {
    WorkerRow row{0, hello.name, hello.version, hello.isa, hello.threads, hello.memory_bytes, wall_seconds()};
    row.id = s.store.add_worker(row);
    WorkerInfo& w = s.workers[row.id];
    w.row = row;
    w.last_seen = Clock::now();
    log_event(spdlog::level::info, "worker.registered",
              {{"worker", row.id}, {"name", hello.name}, {"threads", hello.threads}, {"isa", hello.isa}});
    return json{{"id", row.id},
                {"lease_timeout", s.opt.lease_timeout},
                {"heartbeat_seconds", s.opt.lease_timeout / 4},
                {"max_poll_wait", s.opt.max_poll_wait}};
  } catch (const std::exception& e) {
    return internal_error(e);
  }
}

Result<json> Coordinator::lease(uint64_t worker, double wait_seconds) {
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
  std::unique_lock<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  w->last_seen = Clock::now();
  if (w->state == "draining")
    return make_error(Code::Gone, "drained", "worker " + std::to_string(worker) + " is being drained: no more work");
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                           std::clamp(wait_seconds, 0.0, s.opt.max_poll_wait)));
  for (;;) {
    if (s.stopping) return make_error(Code::Unavailable, "stopping", "the coordinator is shutting down");
    if (w->state == "draining")
      return make_error(Code::Gone, "drained", "worker " + std::to_string(worker) + " is being drained: no more work");
    JobState* best = nullptr;
    size_t unit = 0;
    for (auto& [id, job] : s.jobs) {
      if (is_terminal(job->phase)) continue;
      if (best && (job->priority() < best->priority())) continue;
      if (best && job->priority() == best->priority()) continue;  // same priority: earlier job first
      auto f = job->failures_by_worker.find(worker);
      if (f != job->failures_by_worker.end() && f->second >= s.opt.worker_failure_limit) continue;
      if (std::optional<size_t> u = job->next_unit()) {
        best = job.get();
        unit = *u;
      }
    }
    if (best) {
      try {
        const double now = wall_seconds();
        // The job's first lease: persisted before anything is recorded in memory, so a failed write
        // (a full disk) leaves no lease behind that would hold the unit until it expires.
        if (best->phase == JobPhase::Queued) {
          best->phase = JobPhase::Running;
          best->started = now;
          try {
            s.save_phase(*best);
          } catch (...) {
            best->phase = JobPhase::Queued;
            best->started = 0;
            throw;
          }
          log_event(spdlog::level::info, "job.started", {{"job", best->id()}});
        }
        Lease l;
        l.id = s.store.log_lease(best->id(), best->tile_of(unit), best->pass_of(unit), worker, now);
        l.job_id = best->id();
        l.tile = best->tile_of(unit);
        l.pass = best->pass_of(unit);
        l.rect = best->rect(unit);
        l.sample_begin = best->sample_begin(unit);
        l.sample_end = best->sample_end(unit);
        l.seconds_to_expiry = s.opt.lease_timeout;
        l.settings = best->plan().settings;
        l.scene_file = best->plan().scene_file;
        l.files = best->plan().files;
        best->lease_started(unit);
        s.leases[l.id] = LeaseInfo{l.id, l.job_id, worker, unit,
                                   Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                      std::chrono::duration<double>(s.opt.lease_timeout))};
        w->state = "busy";
        json j = to_json(l);
        const size_t bytes = j.dump().size();
        best->lease_bytes += bytes;
        s.counters.bytes_out += bytes;
        ++s.counters.leased;
        log_event(spdlog::level::debug, "lease.issued",
                  {{"lease", l.id}, {"job", l.job_id}, {"tile", l.tile}, {"pass", l.pass}, {"worker", worker}});
        s.lease_wait.observe(std::chrono::duration<double>(Clock::now() - t0).count());
        return j;
      } catch (const std::exception& e) {
        return internal_error(e);
      }
    }
    if (Clock::now() >= deadline) break;
    if (w->state == "busy") {  // waiting for work with none in hand: idle, as the dashboard shows
      bool holds = false;
      for (auto& [id, l] : s.leases) holds |= l.worker == worker;
      if (!holds) w->state = "idle";
    }
    s.work_cv.wait_until(lock, deadline);
  }
  if (w->state == "busy") {  // (a draining worker keeps its state)
    bool holds = false;
    for (auto& [id, l] : s.leases) holds |= l.worker == worker;
    if (!holds) w->state = "idle";
  }
  s.lease_wait.observe(std::chrono::duration<double>(Clock::now() - t0).count());
  return json();
}

Result<json> Coordinator::heartbeat(uint64_t worker, const json& body) {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  w->last_seen = Clock::now();
  if (w->state == "lost") w->state = "busy";
  json drop = json::array();
  auto leases = body.is_object() ? body.find("leases") : body.end();
  if (body.is_object() && leases != body.end() && leases->is_array()) {
    for (const json& item : *leases) {
      auto number = [&item](const char* key) {
        auto it = item.find(key);
        return it != item.end() && it->is_number_unsigned();
      };
      if (!item.is_object() || !number("id") || !number("job") || !number("tile") || !number("pass"))
        return make_error(Code::BadRequest, "bad_heartbeat",
                          "each lease in 'leases' must be {\"id\", \"job\", \"tile\", \"pass\"} with unsigned integers");
      const uint64_t id = item["id"].get<uint64_t>();
      auto it = s.leases.find(id);
      if (it != s.leases.end() && it->second.worker == worker) {
        auto job = s.jobs.find(it->second.job);
        if (job != s.jobs.end() && job->second->is_done(it->second.unit)) {
          drop.push_back(id);  // someone else delivered it first
          s.end_lease(it);
          continue;
        }
        it->second.expires = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(s.opt.lease_timeout));
        continue;
      }
      // Unknown (a lease from before a coordinator restart): keep it if its work is still wanted.
      const uint64_t job_id = item["job"].get<uint64_t>();
      const uint64_t tile = item["tile"].get<uint64_t>(), pass = item["pass"].get<uint64_t>();
      auto job = s.jobs.find(job_id);
      if (job == s.jobs.end() || is_terminal(job->second->phase) || tile >= job->second->num_tiles() ||
          pass >= job->second->num_passes() || job->second->is_done(job->second->unit(tile, pass))) {
        drop.push_back(id);
        continue;
      }
      size_t unit = job->second->unit(uint32_t(tile), uint32_t(pass));
      job->second->lease_started(unit);
      s.leases[id] = LeaseInfo{id, job_id, worker, unit,
                               Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(s.opt.lease_timeout))};
    }
  }
  return json{{"drop", drop}};
}

Result<json> Coordinator::upload_result(uint64_t worker, uint64_t lease, std::string_view bytes) {
  Impl& s = *impl_;
  const auto t0 = Clock::now();
  TileResult result;
  std::string error;
  if (!decode_tile_result(bytes, result, error, s.opt.limits.max_pixels))
    return make_error(Code::BadRequest, "bad_result", error);
  std::lock_guard<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  w->last_seen = Clock::now();
  auto it = s.jobs.find(result.job_id);
  if (it == s.jobs.end()) return unknown_job(result.job_id);
  JobState& job = *it->second;
  if (job.phase == JobPhase::Cancelled || job.phase == JobPhase::Failed)
    return make_error(Code::Gone, "job_ended", "job " + std::to_string(job.id()) + " is " + phase_name(job.phase));
  if (result.tile >= job.num_tiles() || result.pass >= job.num_passes())
    return make_error(Code::BadRequest, "bad_result", "tile or pass out of range for job " + std::to_string(job.id()));
  const size_t unit = job.unit(result.tile, result.pass);
  if (!(result.film.rect() == job.rect(unit)) || result.sample_begin != job.sample_begin(unit) ||
      result.sample_end != job.sample_end(unit))
    return make_error(Code::BadRequest, "bad_result", "the result's rectangle or samples do not match the unit");
  s.end_leases_if([&](const LeaseInfo& l) { return l.job == job.id() && l.unit == unit && l.worker == worker; });
  if (job.is_done(unit)) {
    ++job.duplicates;
    ++s.counters.duplicates;
    return json{{"accepted", false}, {"duplicate", true}};
  }
  try {
    // Durable before it is acknowledged: the commit fsyncs the WAL.
    if (!s.store.add_result(job.id(), result.tile, result.pass, worker, std::string(bytes), wall_seconds())) {
      ++job.duplicates;
      return json{{"accepted", false}, {"duplicate", true}};
    }
  } catch (const std::exception& e) {
    return internal_error(e);
  }
  const uint64_t samples = job.unit_samples(unit);
  (void)job.add_result(unit, std::move(result.film), worker);
  job.result_bytes += bytes.size();
  ++s.counters.done;
  log_event(spdlog::level::debug, "lease.done",
            {{"lease", lease}, {"job", job.id()}, {"unit", unit}, {"worker", worker}, {"seconds", result.seconds}});
  s.counters.bytes_in += bytes.size();
  w->units_done += 1;
  w->samples_done += samples;
  w->render_seconds += result.seconds;
  if (job.complete()) {
    job.phase = JobPhase::Done;
    job.finished = wall_seconds();
    try {
      s.save_phase(job);
    } catch (const std::exception& e) {
      return internal_error(e);
    }
    log_event(spdlog::level::info, "job.done",
              {{"job", job.id()}, {"seconds", job.finished - job.started}, {"spp", job.spp_complete()},
               {"stopped_at_target", job.converged()}});
  }
  (void)lease;
  s.upload_seconds.observe(std::chrono::duration<double>(Clock::now() - t0).count());
  return json{{"accepted", true}, {"duplicate", false}};
}

Status Coordinator::fail_lease(uint64_t worker, uint64_t lease, const json& body) {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mu);
  auto it = s.leases.find(lease);
  if (it == s.leases.end() || it->second.worker != worker)
    return make_error(Code::NotFound, "unknown_lease", "worker " + std::to_string(worker) + " holds no lease " +
                                                           std::to_string(lease));
  auto job_it = s.jobs.find(it->second.job);
  s.end_lease(it);
  if (job_it == s.jobs.end()) return Status::success();
  JobState& job = *job_it->second;
  std::string reason = body.is_object() && body.contains("error") && body["error"].is_string()
                           ? body["error"].get<std::string>().substr(0, 2000)
                           : "unspecified";
  ++job.failures_by_worker[worker];
  ++s.counters.failed;
  job.last_failure = reason;
  log_event(spdlog::level::warn, "lease.failed", {{"lease", lease}, {"job", job.id()}, {"worker", worker}, {"reason", reason}});
  // The job fails when its work fails on several workers (or on every worker there is).
  size_t live = 0;
  for (auto& [id, w] : s.workers) live += w.state == "idle" || w.state == "busy";
  const size_t needed = std::max<size_t>(1, std::min<size_t>(size_t(s.opt.failed_workers_limit), live));
  if (!is_terminal(job.phase) && job.failures_by_worker.size() >= needed) {
    job.phase = JobPhase::Failed;
    job.finished = wall_seconds();
    job.error = "failed on " + std::to_string(job.failures_by_worker.size()) + " worker(s); last error: " + reason;
    s.end_leases_if([&](const LeaseInfo& l) { return l.job == job.id(); });
    log_event(spdlog::level::err, "job.failed", {{"job", job.id()}, {"reason", job.error}});
  }
  try {
    s.save_phase(job);
  } catch (const std::exception& e) {
    return internal_error(e);
  }
  return Status::success();
}

Status Coordinator::sign_off(uint64_t worker, const json& body) {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  s.end_leases_if([&](const LeaseInfo& l) { return l.worker == worker; });
  w->state = "gone";
  try {
    s.store.touch_worker(worker, wall_seconds(), "gone");
  } catch (const std::exception& e) {
    return internal_error(e);
  }
  log_event(spdlog::level::info, "worker.signed_off", {{"worker", worker}});
  return Status::success();
}

Status Coordinator::drain_worker(uint64_t worker) {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mu);
  WorkerInfo* w = s.find_worker(worker);
  if (!w) return unknown_worker(worker);
  if (w->state == "gone") return make_error(Code::Conflict, "worker_gone", "worker " + std::to_string(worker) + " signed off");
  w->state = "draining";
  s.work_cv.notify_all();  // its waiting polls return now
  log_event(spdlog::level::info, "worker.draining", {{"worker", worker}});
  return Status::success();
}

Result<json> Coordinator::list_workers() {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mu);
  json list = json::array();
  for (auto& [id, w] : s.workers) {
    list.push_back({{"id", id},
                    {"name", w.row.name},
                    {"threads", w.row.threads},
                    {"state", w.state},
                    {"units_done", w.units_done},
                    {"samples_done", w.samples_done},
                    {"samples_per_second", w.render_seconds > 0 ? double(w.samples_done) / w.render_seconds : 0.0}});
  }
  return json{{"workers", list}};
}

}  // namespace tessera::server
