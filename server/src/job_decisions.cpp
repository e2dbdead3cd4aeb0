// What a job decides at its barriers, stored before the passes that depend on it are leased: an
// adaptive pass's per-pixel counts (a group-commit record) and a new artifact (encoded, hashed and
// written off the lock, then its row committed and its passes opened).
#include "coordinator_impl.h"
#include "event_log.h"

#include "tessera/farm/sample_counts.h"
#include "tessera/farm/sha256.h"

#include <spdlog/spdlog.h>

#include <filesystem>

namespace tessera::server {

namespace fs = std::filesystem;

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
      fs::file_time_type written;
      try {
        write_file_durably(guide_path(hash), bytes);
        written = fs::last_write_time(guide_path(hash));
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
      // the artifact is handed out only once its row is durable. A point map's predecessor has
      // no pass left that gathers from it (the barrier that built this one saw them done): its
      // file goes once that is durable.
      const std::optional<std::string> spent = job.spent_by(made.iteration);
      std::optional<fs::file_time_type> spent_written;
      if (auto it = job.artifacts_written.find(made.iteration - 1); spent && it != job.artifacts_written.end()) {
        spent_written = it->second;
        job.artifacts_written.erase(it);
      }
      if (job.plan().points) {
        job.artifacts_written[made.iteration] = written;
        job.latest_map_bytes = made.artifact->memory_bytes();
      }
      (void)commits.append(
          [id, iteration = made.iteration, hash, fed_before = job.first_pass_feeding_after(made.iteration),
           spent = spent.has_value()](Store& st) {
            st.save_guide(id, iteration, hash, fed_before);
            if (spent) st.spend_guide(id, iteration - 1);
          },
          GroupCommit::Retry::UntilDurable, [this, spent, spent_written, hash](bool durable) TESSERA_REQUIRES(mu) {
            if (durable && spent && spent_written && *spent != hash)
              background.push([this, h = *spent, w = *spent_written] { remove_spent_artifact(h, w); });
          });
      log_event(spdlog::level::info, "job.guide_stored",
                {{"job", id}, {"iteration", made.iteration}, {"memory_bytes", made.artifact->memory_bytes()},
                 {"bytes", bytes.size()}, {"barrier_seconds", made.seconds}, {"seconds", seconds}});
      job.artifact_stored(made.iteration, hash);
      work_cv.notify_all();
    });
  }
}

void Coordinator::Impl::remove_spent_artifact(const std::string& hash, fs::file_time_type written) {
  // (Another job may have the same bytes: its row names them, or, still being committed, it wrote
  // the file again since. Either keeps it; retention collects it once no row names it.)
  const fs::path path = guide_path(hash);
  std::error_code ec;
  if (store.guide_named(hash) || fs::last_write_time(path, ec) != written || ec) return;
  fs::remove(path, ec);
}

}  // namespace tessera::server
