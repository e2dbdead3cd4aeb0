#include "job_registry.h"

namespace tessera::server {

JobState* JobRegistry::find(uint64_t id) {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : it->second.get();
}

const JobState* JobRegistry::find(uint64_t id) const {
  auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : it->second.get();
}

void JobRegistry::index(const JobState& job) {
  if (!is_terminal(job.phase())) order_.emplace(-int64_t(job.priority()), job.id());
}

void JobRegistry::unindex(const JobState& job) { order_.erase({-int64_t(job.priority()), job.id()}); }

JobState& JobRegistry::add(std::unique_ptr<JobState> job) {
  if (jobs_.contains(job->id())) return replace(std::move(job));
  JobState& added = *job;
  jobs_.emplace(added.id(), std::move(job));
  index(added);
  return added;
}

JobState& JobRegistry::replace(std::unique_ptr<JobState> job) {
  auto it = jobs_.find(job->id());
  if (it != jobs_.end()) unindex(*it->second);
  JobState& now = *job;
  jobs_[job->id()] = std::move(job);
  index(now);
  return now;
}

void JobRegistry::erase(uint64_t id) {
  auto it = jobs_.find(id);
  if (it == jobs_.end()) return;
  unindex(*it->second);
  jobs_.erase(it);
}

void JobRegistry::set_phase(JobState& job, JobPhase to) {
  unindex(job);
  job.phase_ = to;
  index(job);
}

void JobRegistry::set_priority(JobState& job, int priority) {
  unindex(job);
  job.priority_ = priority;
  index(job);
}

Status JobRegistry::check_active(int max_active) const {
  const int active = int(order_.size()) + slots_;
  if (active < max_active) return Status::success();
  return make_error(Code::TooManyRequests, "too_many_jobs",
                    std::to_string(active) + " jobs are queued or running; the limit is " + std::to_string(max_active) +
                        " (retry when some have finished)");
}

std::vector<JobCandidate> JobRegistry::candidates(const std::function<bool(const JobState&)>& excluded) const {
  std::vector<JobCandidate> out;
  for (const auto& [key, id] : order_) {
    const JobState& job = *jobs_.at(id);
    JobCandidate c{id, job.priority(), job.next_unit(), excluded(job)};
    out.push_back(c);
    if (c.fresh_unit && !c.excluded) break;
  }
  return out;
}

std::map<std::string, int> JobRegistry::count_by_phase() const {
  std::map<std::string, int> counts;
  for (JobPhase p : {JobPhase::Queued, JobPhase::Running, JobPhase::Done, JobPhase::Failed, JobPhase::Cancelled})
    counts[phase_name(p)] = 0;
  for (const auto& [id, job] : jobs_) ++counts[phase_name(job->phase())];
  return counts;
}

}  // namespace tessera::server
