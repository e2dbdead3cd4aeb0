// Workers: registration (with the build check), state changes, sign-off, draining and listing.
#include "coordinator_impl.h"
#include "event_log.h"

#include <spdlog/spdlog.h>

namespace tessera::server {

namespace {
Status unknown_worker(uint64_t id) {
  return make_error(Code::NotFound, "unknown_worker", "no worker " + std::to_string(id) + "; register again");
}
}  // namespace

void Coordinator::Impl::set_worker_state(uint64_t id, WorkerInfo& w, WorkerState to) {
  const std::optional<WorkerRegistry::Change> change = workers.set_state(w, to);
  if (!change) return;
  if (to == WorkerState::Lost) {
    log_event(spdlog::level::warn, "worker.lost", {{"worker", id}, {"name", w.row.name}});
    end_leases(leases.of_worker(id));  // dead: what it held is re-issued now, not at each lease's expiry
  } else if (change->from == WorkerState::Lost) {
    log_event(spdlog::level::info, "worker.back", {{"worker", id}, {"name", w.row.name}});
  }
}

void Coordinator::Impl::saw_worker(uint64_t id, WorkerInfo& w) {
  workers.saw(w);
  if (w.state == WorkerState::Lost) update_busy(id, w);
}

void Coordinator::Impl::update_busy(uint64_t id, WorkerInfo& w) {
  if (w.state == WorkerState::Draining || w.state == WorkerState::Gone) return;
  set_worker_state(id, w, leases.holds(id) ? WorkerState::Busy : WorkerState::Idle);
}

void Coordinator::Impl::adopt_worker(uint64_t id) {
  {
    MutexLock lock(mu);
    if (!workers.needs_adoption(id)) return;
  }
  std::optional<WorkerRow> row = store.worker(id);  // (a store read: off the lock)
  if (!row) return;
  MutexLock lock(mu);
  (void)workers.adopt(*row);
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
    MutexLock lock(s.mu);
    s.workers.add(row);
    log_event(spdlog::level::info, "worker.registered",
              {{"worker", row.id}, {"name", hello.name}, {"threads", hello.threads}, {"isa", hello.isa}});
    return Registration{row.id, s.opt.heartbeat_interval * kMissedHeartbeats, s.opt.heartbeat_interval,
                        s.opt.max_poll_wait};
  } catch (const std::exception& e) {
    return internal_error(e);
  }
}

Status Coordinator::sign_off(uint64_t worker) {
  Impl& s = *impl_;
  s.adopt_worker(worker);
  uint64_t ticket = 0;
  {
    MutexLock lock(s.mu);
    WorkerInfo* w = s.workers.find(worker);
    if (!w) return unknown_worker(worker);
    s.end_leases(s.leases.of_worker(worker));
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
  MutexLock lock(s.mu);
  WorkerInfo* w = s.workers.find(worker);
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
  MutexLock lock(s.mu);
  std::vector<WorkerStatus> list;
  for (const auto& [id, w] : s.workers.all())
    list.push_back({id, w.row.name, worker_state_name(w.state), int(w.row.threads), w.units_done, w.samples_done,
                    w.render_seconds > 0 ? double(w.samples_done) / w.render_seconds : 0.0, w.memory.scene_bytes,
                    w.memory.scenes, w.row.memory});
  return list;
}

}  // namespace tessera::server
