// The one place a job's phase changes (coordinator_impl.h, change_phase):
//
//   Queued -> Running                 its first lease
//   Queued/Running -> Done            its last planned unit arrived (or it stopped at its target)
//   Queued/Running -> Failed          its work failed on too many workers
//   Queued/Running -> Cancelled       a client cancelled it
//   Failed/Cancelled -> Queued        a client retried it (keeping the passes it has)
//
// Each change sets the job's times, is appended to the group commit (in the order of the leases and
// results around it; kept until durable, so a full disk delays it but never loses it), ends the
// job's leases when it ends, and is logged; an ended job's image is written and its webhook called
// (finish_job).
#include "coordinator_impl.h"
#include "event_log.h"

#include <spdlog/spdlog.h>

namespace tessera::server {

namespace {

bool allowed(JobPhase from, JobPhase to) {
  switch (to) {
    case JobPhase::Running: return from == JobPhase::Queued;
    case JobPhase::Done:
    case JobPhase::Failed:
    case JobPhase::Cancelled: return !is_terminal(from);
    case JobPhase::Queued: return from == JobPhase::Failed || from == JobPhase::Cancelled;
  }
  return false;
}

void log_change(const JobState& job, JobPhase to) {
  const uint64_t id = job.id();
  switch (to) {
    case JobPhase::Running: return log_event(spdlog::level::info, "job.started", {{"job", id}});
    case JobPhase::Done:
      return log_event(spdlog::level::info, "job.done",
                       {{"job", id}, {"seconds", job.finished - job.started}, {"spp", job.spp_complete()},
                        {"stopped_at_target", job.converged()}});
    case JobPhase::Failed: return log_event(spdlog::level::err, "job.failed", {{"job", id}, {"reason", job.error}});
    case JobPhase::Cancelled: return log_event(spdlog::level::info, "job.cancelled", {{"job", id}});
    case JobPhase::Queued:
      return log_event(spdlog::level::info, "job.retried",
                       {{"job", id}, {"units_done", job.done_units()}, {"units", job.num_units()}});
  }
}

}  // namespace

uint64_t Coordinator::Impl::change_phase(JobState& job, JobPhase to, const std::string& error) {
  if (!allowed(job.phase(), to))
    throw std::logic_error(std::string("job ") + std::to_string(job.id()) + ": no transition from " +
                           phase_name(job.phase()) + " to " + phase_name(to));
  const double now = wall_seconds();
  jobs.set_phase(job, to);
  if (to == JobPhase::Running) job.started = now;
  if (is_terminal(to)) job.finished = now;
  if (to == JobPhase::Failed) job.error = error;
  if (to == JobPhase::Queued) {
    job.finished = 0;
    job.error.clear();
  }
  const uint64_t ticket = append_phase(job);
  if (is_terminal(to)) end_leases(leases.of_job(job.id()));
  log_change(job, to);
  work_cv.notify_all();
  if (is_terminal(to)) finish_job(job, /*notify=*/true);
  return ticket;
}

uint64_t Coordinator::Impl::append_phase(const JobState& job) {
  return commits.append(
      [id = job.id(), phase = std::string(phase_name(job.phase())), error = job.error, started = job.started,
       finished = job.finished](Store& st) { st.set_job_state(id, phase, error, started, finished); },
      GroupCommit::Retry::UntilDurable);
}

void Coordinator::Impl::send_webhook(const JobState& job) {
  if (job.plan().settings.webhook.empty()) return;
  // The body is made on the sender's thread: the lease log's counts are store reads.
  webhooks.send(job.id(), job.plan().settings.webhook, [this, status = status_of(job)]() mutable {
    add_lease_counts(status);
    return to_json(status).dump();
  });
}

}  // namespace tessera::server
