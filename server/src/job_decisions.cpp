// What a job decides at its barriers, stored before the passes that depend on it are leased: an
// adaptive pass's per-pixel counts (a group-commit record) and a new artifact (encoded, hashed and
// written off the lock, then its row committed and its passes opened).
#include "coordinator_impl.h"
#include "event_log.h"

#include "tessera/farm/sample_counts.h"
#include "tessera/farm/sha256.h"

#include <spdlog/spdlog.h>

namespace tessera::server {

void Coordinator::Impl::save_decisions(JobState& job) {
  save_pass_plans(job);
  save_artifacts(job);
}

void Coordinator::Impl::save_pass_plans(JobState& job) {
  for (PassSequencer::DecidedPass& d : job.take_new_plans()) {
    log_event(spdlog::level::info, "job.pass_planned", {{"job", job.id()}, {"pass", d.pass}, {"seconds", d.seconds}});
    // Retried until stored, ahead of the leases appended after it: a lease of the pass is only
    // handed out once its counts are durable.
    auto counts = std::make_shared<const std::vector<uint32_t>>(std::move(d.counts));
    (void)commits.append([id = job.id(), pass = d.pass, counts](Store& st) {
      st.save_pass_plan(id, pass, encode_sample_counts(*counts));
    }, GroupCommit::Retry::UntilDurable);
  }
}

void Coordinator::Impl::save_artifacts(JobState& job) {
  while (auto made = job.take_artifact()) {
    background.push([this, id = job.id(), made = std::move(*made)] {
      const auto t0 = std::chrono::steady_clock::now();
      const std::string bytes = made.artifact->encode(), hash = sha256_hex(bytes);
      std::string error;
      try {
        write_file_durably(guide_path(hash), bytes);
      } catch (const std::exception& e) {
        error = e.what();
      }
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      MutexLock lock(mu);
      JobState* found = jobs.find(id);
      if (!found || is_terminal(found->phase())) return;
      JobState& job = *found;
      if (!error.empty()) {
        (void)change_phase(job, JobPhase::Failed, "cannot store the job's guide: " + error);
        return;
      }
      // Retried until stored, ahead of the leases appended after it: a lease that renders with
      // the artifact is handed out only once its row is durable.
      (void)commits.append([id, iteration = made.iteration, hash](Store& st) { st.save_guide(id, iteration, hash); },
                           GroupCommit::Retry::UntilDurable);
      log_event(spdlog::level::info, "job.guide_stored",
                {{"job", id}, {"iteration", made.iteration}, {"memory_bytes", made.artifact->memory_bytes()},
                 {"bytes", bytes.size()}, {"barrier_seconds", made.seconds}, {"seconds", seconds}});
      job.artifact_stored(made.iteration, hash);
      work_cv.notify_all();
    });
  }
}

}  // namespace tessera::server
