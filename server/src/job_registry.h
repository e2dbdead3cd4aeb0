// The coordinator's jobs: every job it knows by id, the active ones (queued or running) in the
// order the scheduler serves them (priority, then submission), and the slots of submissions being
// stored. set_phase() is the one place a job's phase changes and set_priority() the one place its
// priority does, so the order is always the jobs' own. Not thread-safe: the coordinator guards it
// with its mutex.
#pragma once

#include "job_state.h"
#include "scheduler.h"
#include "tessera/server/status.h"

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace tessera::server {

class JobRegistry {
 public:
  JobState* find(uint64_t id);
  const JobState* find(uint64_t id) const;
  /// A job enters (in the phase it has: a rebuilt job may have ended).
  JobState& add(std::unique_ptr<JobState> job);
  /// A job rebuilt in place of the one of its id (a retry).
  JobState& replace(std::unique_ptr<JobState> job);
  void erase(uint64_t id);

  /// The one place a job's phase changes.
  void set_phase(JobState& job, JobPhase to);
  void set_priority(JobState& job, int priority);

  size_t size() const { return jobs_.size(); }
  /// Queued and running jobs.
  size_t active() const { return order_.size(); }
  /// A submission being stored holds a slot, which counts against the limit of active jobs.
  void take_slot() { ++slots_; }
  void give_back_slot() { --slots_; }
  /// 429 when `max_active` jobs are active or being stored.
  Status check_active(int max_active) const;

  /// The scheduler's candidates (scheduler.h): active jobs in its order, up to and including the
  /// first with a fresh unit that `excluded` does not bar it from. A job after it can win neither
  /// a fresh unit nor a speculative copy (its priority is not above that job's), so the jobs
  /// behind are not looked at.
  std::vector<JobCandidate> candidates(const std::function<bool(const JobState&)>& excluded) const;

  /// Every job, by id.
  const std::map<uint64_t, std::unique_ptr<JobState>>& all() const { return jobs_; }
  std::map<std::string, int> count_by_phase() const;

 private:
  void index(const JobState& job);
  void unindex(const JobState& job);

  std::map<uint64_t, std::unique_ptr<JobState>> jobs_;
  std::set<std::pair<int64_t, uint64_t>> order_;  // active jobs: (-priority, id)
  int slots_ = 0;
};

}  // namespace tessera::server
